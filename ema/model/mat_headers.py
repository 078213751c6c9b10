"""What a MATLAB (v5 to 7.2) file's variables are, read from their headers alone: each one's name and dimensions,
before any is loaded.

A compressed variable is a zlib stream whose first few hundred bytes hold its header; a file of 1.5 MB can hold
four arrays of 50 million zeros, 1.6 GB once loaded. So the reader decompresses at most ``HEADER_BYTES`` of each
variable to read its dimensions, and loads only the variables a log map names once each is known to fit a window
(``ema.model.log_files``). A file that is no v5 file (v4, v7.3) says so by its header and is left to the loader.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

HEADER_BYTES = 256  # of a compressed variable decompressed to read its header: its tags, flags, dims and name
MI_INT8, MI_INT32, MI_UINT32, MI_MATRIX, MI_COMPRESSED = 1, 5, 6, 14, 15


def _element(data: bytes, at: int, order: str) -> tuple[int, bytes, int]:
    """(type, payload, next offset) of the data element at ``at``: its tag, in the small format where it packs
    four bytes or fewer into the tag itself."""
    first, second = struct.unpack_from(order + "II", data, at)
    if first >> 16:  # small data element: size in the upper half, data in the second word
        size = first >> 16
        return first & 0xFFFF, data[at + 4 : at + 4 + size], at + 8
    payload = data[at + 8 : at + 8 + second]
    return first, payload, at + 8 + second + (-second % 8)


def _matrix_header(data: bytes, order: str) -> tuple[str, tuple[int, ...]] | None:
    """(name, dimensions) of a miMATRIX element's content (its flags, dimensions and name subelements)."""
    try:
        _, _, at = _element(data, 0, order)  # array flags
        kind, dims, at = _element(data, at, order)
        if kind != MI_INT32:
            return None
        _, name, _ = _element(data, at, order)
    except struct.error:
        return None
    shape = struct.unpack(order + f"{len(dims) // 4}i", dims[: len(dims) // 4 * 4])
    return name.decode("latin-1").rstrip("\x00"), tuple(shape)


def variable_shapes(path: Path) -> dict[str, tuple[int, ...]] | None:
    """Each variable's dimensions, read from its header alone (module docstring); None where the file is no v5
    MATLAB file (the loader then says what it is)."""
    with path.open("rb") as handle:
        header = handle.read(128)
        if len(header) < 128 or header[126:128] not in (b"IM", b"MI"):
            return None
        order = "<" if header[126:128] == b"IM" else ">"
        shapes: dict[str, tuple[int, ...]] = {}
        while tag := handle.read(8):
            if len(tag) < 8:
                break
            kind, size = struct.unpack(order + "II", tag)
            start = handle.tell()
            if kind == MI_COMPRESSED:
                inflated = _inflated_head(handle, size)
                if len(inflated) >= 8 and struct.unpack_from(order + "I", inflated)[0] == MI_MATRIX:
                    found = _matrix_header(inflated[8:], order)
                    if found is not None:
                        shapes[found[0]] = found[1]
            elif kind == MI_MATRIX:
                found = _matrix_header(handle.read(min(size, HEADER_BYTES)), order)
                if found is not None:
                    shapes[found[0]] = found[1]
            handle.seek(start + size + (-size % 8 if kind != MI_COMPRESSED else 0))
    return shapes


def _inflated_head(handle, size: int) -> bytes:  # type: ignore[no-untyped-def]
    """At most ``HEADER_BYTES`` of a compressed element's stream, whatever it inflates to."""
    inflater = zlib.decompressobj()
    out, read = b"", 0
    while len(out) < HEADER_BYTES and read < size:
        chunk = handle.read(min(4096, size - read))
        if not chunk:
            break
        read += len(chunk)
        try:
            out += inflater.decompress(chunk, HEADER_BYTES - len(out))
        except zlib.error:
            break
    return out
