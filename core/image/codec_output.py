"""What the C image libraries print themselves while decoding, collected instead of shown.

libpng ("IDAT: CRC error"), libjpeg ("Corrupt JPEG data: premature end of data segment") and libtiff
write on the process's standard error, below Python: a corrupt file gave two lines (theirs, then
weft's) and a recoverable one a warning on a successful run. :func:`_codec_output` collects those
lines while a file is decoded, so :func:`weft.core.image.load_image` can say what is wrong in one line
of its own, and :func:`_scan_damage` tells from libjpeg's words whether a JPEG's pixels are damaged.
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import tempfile
import threading

_CODEC_LOCK = threading.Lock()
# Lines the image libraries print themselves (on the process's stderr, below Python).
_CODEC_LINE = re.compile(
    r"^(libpng (warning|error)|Corrupt JPEG data|Premature end of JPEG|Warning:|Invalid SOS|"
    r"Bogus |Unsupported marker|TIFF|.*: (Warning|Error), )"
)
# libjpeg's warnings that mean the scan (the pixels) is damaged; stray bytes before the end marker
# (a few, after a whole scan) are harmless and are not among them.
_JPEG_DAMAGE = re.compile(
    r"premature end of data segment|Premature end of JPEG file|bad Huffman code|"
    r"must resync|Invalid SOS|extraneous bytes before marker 0xd[0-7]"
)
_JPEG_STRAY = re.compile(r"(\d+) extraneous bytes before marker 0xd9")
_STRAY_BYTES_OK = 16


@contextlib.contextmanager
def _codec_output(said: list[str]):
    """Collect what the C image libraries print on file descriptor 2 while decoding (libpng's
    "IDAT: CRC error", libjpeg's "Corrupt JPEG data: ...") into ``said`` instead of the terminal:
    weft says what is wrong in one line of its own. Anything else written there meanwhile (another
    thread's line) is passed on."""
    with _CODEC_LOCK:
        try:
            sys.stderr.flush()
            saved = os.dup(2)
        except (OSError, ValueError, AttributeError):
            yield
            return
        try:
            sink = tempfile.TemporaryFile()
        except OSError:
            os.close(saved)
            yield
            return
        try:
            os.dup2(sink.fileno(), 2)
            try:
                yield
            finally:
                os.dup2(saved, 2)
            sink.seek(0)
            text = sink.read(1 << 16).decode("utf-8", "replace")
        finally:
            os.close(saved)
            sink.close()
    other: list[str] = []
    for line in text.splitlines():
        (said if _CODEC_LINE.match(line) else other).append(line)
    if other:
        with contextlib.suppress(OSError, ValueError):
            os.write(2, ("\n".join(other) + "\n").encode("utf-8", "replace"))


def _scan_damage(said: list[str]) -> str | None:
    """libjpeg's words for a damaged scan among ``said``, or None when the pixels are whole."""
    for line in said:
        if _JPEG_DAMAGE.search(line):
            return line.removeprefix("Corrupt JPEG data: ")
        stray = _JPEG_STRAY.search(line)
        if stray and int(stray.group(1)) > _STRAY_BYTES_OK:
            return f"the scan ends {stray.group(1)} bytes before its end marker"
    return None
