"""The command line: thin faces over the Python API, one module per command."""
