"""scenegrep: find the moments in labeled perception data that match a scenario."""

__version__ = "0.1.0"


def __getattr__(name: str):
    """``scenegrep.open_dataset`` and ``scenegrep.Dataset``, imported on first use (the command
    line's start-up does not load the dataset engine)."""
    if name in ("open_dataset", "Dataset"):
        from . import dataset

        return getattr(dataset, name)
    raise AttributeError(f"module 'scenegrep' has no attribute {name!r}")
