"""The package's version, in a module of its own so that the modules that record it (the
files' ``varmech_version``) need not import the package.

Its one source is the workspace's version in Cargo.toml (``[workspace.package]``): maturin gives
it to the package's metadata (pyproject.toml's ``dynamic = ["version"]``), read here, so a wheel
and an editable install both say the version they were built with
(tests/python/test_packaging.py checks that they agree)."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("varmech")
except PackageNotFoundError:  # the source tree on sys.path, never installed: no metadata to read
    __version__ = "0+unknown"
