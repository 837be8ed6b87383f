"""The camtool version, named in what camtool writes (program notes, verify and batch reports).

It sits in the model, the bottom layer, so that every stage can name it without importing
the package root (``camtool/__init__.py``, the public API, which stands above every stage);
``camtool.__version__`` is this value. pyproject.toml gives the same number to the package.
"""

__version__ = "0.1.0"
"""The camtool release (semantic versioning)."""
