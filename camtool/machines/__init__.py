"""Built-in machine profiles (``<name>.toml``), read by :mod:`camtool.model.machine`."""
