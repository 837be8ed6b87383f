"""Text files written with a byte-order mark: UTF-16 and UTF-32 as well as UTF-8.

Windows programs save "Unicode" text as UTF-16 with a byte-order mark (Notepad's
"Unicode", Excel's "Unicode Text (*.txt)"); read as UTF-8 or Latin-1, every other byte
is a NUL. The mark says which encoding it is (Unicode 15, §23.8), so such a file is read
as the text it holds.
"""

from __future__ import annotations

import codecs

_MARKS = (  # longest first: the UTF-32 LE mark begins with the UTF-16 LE one
    (codecs.BOM_UTF32_LE, "utf-32"),
    (codecs.BOM_UTF32_BE, "utf-32"),
    (codecs.BOM_UTF8, "utf-8-sig"),
    (codecs.BOM_UTF16_LE, "utf-16"),
    (codecs.BOM_UTF16_BE, "utf-16"),
)


def marked_encoding(data: bytes) -> str | None:
    """The codec a byte-order mark at the start of ``data`` names (None: no mark)."""
    for mark, codec in _MARKS:
        if data.startswith(mark):
            return codec
    return None


def decoded(data: bytes, errors: str = "strict") -> str:
    """``data`` as text in the encoding its byte-order mark names, else UTF-8; the mark dropped.

    Raises:
        UnicodeDecodeError: (``errors="strict"``) the bytes are not text in that encoding.
    """
    return data.decode(marked_encoding(data) or "utf-8", errors)
