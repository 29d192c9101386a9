"""The version of gcalign, in a module of its own: any layer may read it without importing
the package's lazy Python API."""

__version__ = "0.1.0"
