"""Built-in machine profiles (``<name>.toml``), loaded by :func:`camtool.machine.load_machine`."""
