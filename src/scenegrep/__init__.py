"""scenegrep: find the moments in labeled perception data that match a scenario."""

__version__ = "0.1.0"
