"""The Scenic language front end shared by scene and scenario queries: Scenic parser -> adapter -> IR."""
