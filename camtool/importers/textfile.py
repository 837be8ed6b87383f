"""Text files written with a byte-order mark: UTF-16 and UTF-32 as well as UTF-8.

Windows programs save "Unicode" text as UTF-16 with a byte-order mark (Notepad's
"Unicode", Excel's "Unicode Text (*.txt)"); read as UTF-8 or Latin-1, every other byte
is a NUL. The mark says which encoding it is (Unicode 15, §23.8), so such a file is read
as the text it holds. Without a mark, a file whose every other byte is a NUL and none of
the others is (ASCII text in UTF-16, as some converters write it) is read as UTF-16 in
that byte order: G-code and point lists are ASCII, and UTF-8 text holds no NUL.

Their lines end at LF, CR LF or CR only (:func:`text_lines`), as a controller and numpy
read them. A G-code program that is no UTF-8 is read as Latin-1, unless it holds binary data
(:func:`program_text`).
"""

from __future__ import annotations

import codecs
import re

from camtool.model.errors import InputError

_MARKS = (  # longest first: the UTF-32 LE mark begins with the UTF-16 LE one
    (codecs.BOM_UTF32_LE, "utf-32"),
    (codecs.BOM_UTF32_BE, "utf-32"),
    (codecs.BOM_UTF8, "utf-8-sig"),
    (codecs.BOM_UTF16_LE, "utf-16"),
    (codecs.BOM_UTF16_BE, "utf-16"),
)


def text_encoding(data: bytes) -> str | None:
    """The codec a byte-order mark at the start of ``data`` names, else ``None``.

    Without a mark, ``utf-16-le`` or ``utf-16-be`` for ASCII text in UTF-16 (every
    other byte a NUL, none of the others: see the module).
    """
    for mark, codec in _MARKS:
        if data.startswith(mark):
            return codec
    if len(data) >= 2 and len(data) % 2 == 0:
        even, odd = data[0::2], data[1::2]
        if not odd.strip(b"\0") and b"\0" not in even:
            return "utf-16-le"
        if not even.strip(b"\0") and b"\0" not in odd:
            return "utf-16-be"
    return None


def decoded(data: bytes, errors: str = "strict") -> str:
    """``data`` as text in its :func:`text_encoding`, else UTF-8; a byte-order mark dropped.

    Raises:
        UnicodeDecodeError: (``errors="strict"``) the bytes are not text in that encoding.
    """
    return data.decode(text_encoding(data) or "utf-8", errors)


class BinaryData(ValueError):
    """Bytes that are no text in any encoding camtool reads (:func:`decoded_or_latin1`).

    Its message names the first byte that says so, from the start of the file, and its line
    (1 for the first; lines end at LF, CR LF or CR).
    """


_CONTROL = re.compile(rb"[\x00-\x08\x0e-\x19\x1b-\x1f]")
"""C0 control bytes that no text holds: tab, LF, VT, FF and CR are text, and so is SUB
(0x1A, the end-of-file mark of CP/M and DOS editors)."""
_LINE_END_BYTES = re.compile(rb"\r\n|\r|\n")


def decoded_or_latin1(data: bytes) -> str:
    """:func:`decoded`, or Latin-1 where that fails: every byte is then one character.

    For G-code: a marked file that does not decode is read as Latin-1 too, and the reader
    names the first character that is no G-code. A UTF-8 mark is dropped first (an editor
    wrote it, and a byte after it that is no UTF-8 is the one to name, not the mark).
    Latin-1 text holds no C0 control byte but tab, the line ends and SUB: bytes that are
    no UTF-8 and hold one are binary data (a compressed file, an archive), not text.

    Raises:
        BinaryData: the bytes are no UTF-8 and hold such a control byte.
    """
    try:
        return decoded(data)
    except UnicodeDecodeError:
        control = _CONTROL.search(data)
        if control is not None:
            offset = control.start()
            line = 1 + len(_LINE_END_BYTES.findall(data, 0, offset))
            raise BinaryData(f"byte {offset}, on line {line}, is 0x{data[offset]:02X}") from None
        return data.removeprefix(codecs.BOM_UTF8).decode("latin-1")


def program_text(data: bytes, source: str) -> str:
    """A G-code program's bytes as text (:func:`decoded_or_latin1`).

    Raises:
        InputError: the bytes are binary data, not text; the message names the byte.
    """
    try:
        return decoded_or_latin1(data)
    except BinaryData as exc:
        raise InputError(
            f"{source}: binary data, not a G-code text file: {exc}, a control character "
            "that no text holds; is it compressed (.gz, .zip), an archive or another "
            "program's own file? Give camtool the program as text (.nc, .ngc, .gcode, .tap)"
        ) from None


_LINE_END = re.compile(r"\r\n|\r|\n")


def text_lines(text: str) -> list[str]:
    """``text`` split at its line ends: LF, CR LF and CR only, without the ends.

    ``str.splitlines`` also splits at a form feed, a vertical tab, U+001C-U+001E, U+0085,
    U+2028 and U+2029, which Python's own file reading (universal newlines), numpy's
    ``loadtxt`` and a controller keep inside the line: a point list's ``# note`` holding a
    U+2028 would give a row of the numbers after it. As ``splitlines``, a last line end
    gives no empty line after it.
    """
    if text.isascii() and not any(c in text for c in _ASCII_BREAKS):
        return text.splitlines()  # the same lines, made faster
    lines = _LINE_END.split(text)
    if lines[-1] == "":
        lines.pop()
    return lines


_ASCII_BREAKS = "\x0b\x0c\x1c\x1d\x1e"
"""The line breaks of ``str.splitlines`` in ASCII other than LF and CR."""
