"""Small TOML files (job, machine and target files) and other small text files read safely.

One reader for every small file a user hands camtool (:func:`read_small_text`; the TOML
files through :func:`read_toml_file`, measurement sheets too): only a regular file (a FIFO or
a device such as ``/dev/zero`` is refused before it is read, so nothing blocks or
fills memory), at most a given size, UTF-8 (a byte-order mark is dropped), nested no
deeper than such a file needs (tomllib recurses per level).
"""

from __future__ import annotations

import datetime
import json
import math
import os
import re
import stat
import tomllib
from pathlib import Path
from typing import Any

from camtool.model.errors import InputError

SMALL_TOML_BYTES = 1 << 20
"""The largest machine or target file read, bytes (the built-in ones are under 20 KB)."""


def read_small_text(path: str | Path, *, what: str, limit_bytes: int) -> str:
    """A small text file read safely: a regular file, its size bounded, UTF-8.

    A FIFO or a device is refused before it is read (opened without blocking, checked
    with ``fstat``); a byte-order mark is dropped.

    Args:
        path: the file.
        what: what the file is, for messages (``"job file"``, ``"measurement sheet"``).
        limit_bytes: the largest file read.

    Raises:
        InputError: missing or unreadable, not a regular file, larger than
            ``limit_bytes``, or not UTF-8 text; each message names the file.
    """
    name = str(path)
    try:
        fd = os.open(name, os.O_RDONLY | os.O_NONBLOCK)
    except OSError as exc:
        raise InputError(f"{name}: cannot read the {what} ({exc.strerror or exc})") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise InputError(f"{name}: the {what} is not a regular file")
        if info.st_size > limit_bytes:
            raise InputError(
                f"{name}: the {what} is {info.st_size} bytes, more than {limit_bytes}; "
                f"is it a {what}?"
            )
        with os.fdopen(os.dup(fd), "rb") as stream:
            data = stream.read(limit_bytes + 1)
    except OSError as exc:
        raise InputError(f"{name}: cannot read the {what} ({exc.strerror or exc})") from None
    finally:
        os.close(fd)
    if len(data) > limit_bytes:
        raise InputError(f"{name}: the {what} is larger than {limit_bytes} bytes")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{name}: the {what} is not UTF-8 text (byte {exc.start}); save it as UTF-8"
        ) from None
    return text[1:] if text.startswith("\ufeff") else text


def read_toml_file(path: str | Path, *, what: str, limit_bytes: int) -> dict[str, Any]:
    """A small TOML file read safely (:func:`read_small_text`), nesting bounded.

    Args:
        path: the file.
        what: what the file is, for messages (``"job file"``).
        limit_bytes: the largest file read.

    Raises:
        InputError: not a regular file (a FIFO or a device is not opened for reading), too
            large, not UTF-8 text, or not TOML (the message gives tomllib's line and
            column); nested more deeply than any such file needs.
    """
    name = str(path)
    text = read_small_text(path, what=what, limit_bytes=limit_bytes)
    if re.search(r"[\[{]{64}", text.replace(" ", "")):
        raise InputError(f"{name}: the {what} nests arrays or tables more than 64 deep")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{name}: the {what} is not valid TOML ({exc})") from None
    except RecursionError:
        raise InputError(f"{name}: the {what} nests arrays or tables too deeply") from None


def as_toml(value: object) -> str:
    """``value`` as a TOML file writes it, for messages that quote a key's value.

    ``true``/``false``, a string in double quotes (JSON's escapes, which TOML's basic
    strings share; DEL escaped), ``inf``/``nan``, arrays in brackets, tables inline, dates
    in ISO 8601 (TOML 1.0): ``side = false`` is quoted as written, not as Python's ``False``.
    """
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, list | tuple):
        return "[" + ", ".join(as_toml(v) for v in value) + "]"
    if isinstance(value, dict):
        pairs = (f"{_toml_key(str(k))} = {as_toml(v)}" for k, v in value.items())
        return "{ " + ", ".join(pairs) + " }" if value else "{}"
    if isinstance(value, datetime.date | datetime.time):
        return value.isoformat()
    return str(value)


def _toml_key(key: str) -> str:
    """A key bare when TOML allows it, else quoted."""
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", key) else _toml_string(key)


def _toml_string(text: str) -> str:
    """A TOML basic string: JSON's escapes, and DEL escaped too (TOML forbids it bare)."""
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")
