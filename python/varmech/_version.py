"""The package's version, in a module of its own so that the modules that record it (the
files' ``varmech_version``) need not import the package."""

__version__ = "0.1.0"
