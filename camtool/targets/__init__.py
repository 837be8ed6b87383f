"""Built-in target files (``<name>.toml``): a dialect plus a machine profile."""
