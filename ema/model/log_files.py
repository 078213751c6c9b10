"""A logged file as named columns and constants: CSV (read as a stream), MATLAB (``.mat``), NumPy (``.npz``) or a
recorder's JSON (a header of constants and one object a sample).

Limits are checked before the work: a file over ``MAX_LOG_BYTES`` is refused from its size, and a CSV is
read row by row and refused at its ``MAX_ROWS + 1``-th row (a window holds at most ``MAX_SAMPLES``), so a
huge file costs neither minutes nor gigabytes. Errors name the file, and the variable where one is at fault.
"""

from __future__ import annotations

import csv
import io
import math
import zipfile
from collections.abc import Collection, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ema.model.bounds import MAX_SAMPLES
from ema.model.checks import InputError, load_json
from ema.model.mat_headers import variable_shapes

MAX_LOG_BYTES = 256 * 2**20  # a logged file's size limit: ~4x the largest window's CSV
MAX_ROWS = MAX_SAMPLES  # as many rows as a window's samples at most
MAX_JSON_LOG_BYTES = 64 * 2**20  # a recorder's JSON is parsed whole: a smaller limit than a streamed CSV's
TABLE_SUFFIXES = (".csv", ".mat", ".npz", ".json")


@dataclass(frozen=True)
class Table:
    """A file's numeric columns (1-D, one length each), its scalar constants and its ``# key: value`` lines."""

    columns: dict[str, np.ndarray]
    scalars: dict[str, float] = field(default_factory=dict)
    meta: dict[str, str] = field(default_factory=dict)
    unread: dict[str, str] = field(default_factory=dict)  # a CSV column left out as text -> its first such cell
    present: tuple[str, ...] = ()  # every variable's name, those left unloaded too (a MATLAB file's)

    def numeric(self, name: str, path: Path, what: str) -> np.ndarray:
        """The column ``name``; an InputError naming the file and the variable, saying what it holds instead (text, a
        matrix, a struct: ``unread``), or where only the case of its name differs, the name the file has."""
        if name in self.columns:
            return self.columns[name]
        if name in self.unread:
            raise InputError(f"{path}: {name}", f"{self.unread[name]} ({what})")
        alike = [other for other in (*self.columns, *self.unread, *self.present) if other.lower() == name.lower()]
        if alike:
            raise InputError(str(path), f"has no variable {name!r}, but {alike[0]!r}: names differ in case ({what})")
        raise InputError(str(path), f"has no numeric variable {name!r} ({what})")


def read_table(path: str | Path, names: Collection[str] | None = None) -> Table:
    """The table in ``path`` by its suffix; InputError naming the file where it cannot be read or is too large.
    ``names``: the variables wanted (a log map's), where the format can leave the others unread (a MATLAB file's:
    its others never loaded, whatever they would inflate to)."""
    path = Path(path)
    readers = {".csv": _csv, ".mat": _mat, ".npz": _npz, ".json": _json}
    suffix = path.suffix.lower()
    if suffix not in readers:
        raise InputError(str(path), f"is not a {'/'.join(TABLE_SUFFIXES)} file")
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise InputError(str(path), f"cannot be read ({exc.strerror})") from None
    if size == 0:
        raise InputError(str(path), "is empty (0 bytes)")
    if suffix == ".json" and size > MAX_JSON_LOG_BYTES:
        raise InputError(
            str(path),
            f"is {size / 2**20:.0f} MiB, over the {MAX_JSON_LOG_BYTES // 2**20} MiB a JSON log may be: cut it",
        )
    if size > MAX_LOG_BYTES:
        raise InputError(
            str(path), f"is {size / 2**20:.0f} MiB, over the {MAX_LOG_BYTES // 2**20} MiB a logged file may be: cut it"
        )
    return _mat(path, names) if suffix == ".mat" else readers[suffix](path)


def _rows(handle: io.TextIOBase, meta: dict[str, str]) -> Iterator[str]:
    """The data lines of a CSV, its ``# key: value`` lines kept in ``meta``."""
    for line in handle:
        if line.startswith("#"):
            key, colon, value = line[1:].partition(":")
            if colon:
                meta[key.strip()] = value.strip()
            continue
        yield line


def _csv(path: Path) -> Table:
    """A CSV's numeric columns (a column with any non-number is text: left out), read row by row."""
    meta: dict[str, str] = {}
    try:
        with path.open(newline="", encoding="utf-8") as handle:
            reader = csv.reader(_rows(handle, meta))
            header = next(reader, None)
            if header is None:
                raise InputError(str(path), "has no header row")
            values: list[list[float | None]] = [[] for _ in header]
            count = 0
            for count, row in enumerate(reader, start=1):  # count: the rows read
                if count > MAX_ROWS:
                    raise InputError(str(path), f"has over {MAX_ROWS:,} rows, more than a window may hold: cut it")
                for column, text in zip(values, row, strict=False):
                    column.append(_number(text))
    except UnicodeDecodeError:
        raise InputError(str(path), "is not text (a CSV is UTF-8)") from None
    except csv.Error as exc:
        raise InputError(str(path), f"is not a CSV ({exc})") from None
    if count == 0:
        raise InputError(str(path), "has no data rows")
    columns, unread = {}, {}
    for name, column in zip(header, values, strict=True):
        if len(column) < count:
            unread[name.strip()] = f"is not numeric throughout: data row {len(column) + 1} lacks it"
        elif None in column:
            unread[name.strip()] = f"is not numeric throughout: data row {column.index(None) + 1} holds no number"
        else:
            columns[name.strip()] = np.array(column, dtype=np.float64)
    return Table(columns, meta=meta, unread=unread)


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _mat(path: Path, names: Collection[str] | None = None) -> Table:
    """A MATLAB file's vectors (any n×1 or 1×n) as columns, its 1×1 values as constants: of ``names`` only where
    given, each refused from its header where it holds more numbers than a window may (``ema.model.mat_headers``:
    before it is inflated, however well it compresses)."""
    from scipy.io import loadmat  # the reader of MATLAB's files; imported only for one
    from scipy.io.matlab import MatReadError

    shapes = variable_shapes(path)
    wanted = None if names is None or shapes is None else [name for name in names if name in shapes]
    for name, shape in (shapes or {}).items():
        if (wanted is None or name in wanted) and math.prod(shape) > MAX_ROWS:
            dims = "×".join(f"{d:,}" for d in shape)
            raise InputError(
                f"{path}: {name}", f"is a {dims} array, more than a window may hold: refused before it is read"
            )
    try:
        variables = loadmat(path, squeeze_me=False, variable_names=wanted)
    except NotImplementedError:
        raise InputError(str(path), "is a MATLAB 7.3 (HDF5) file: save it with -v7 (scipy reads up to 7.2)") from None
    except (MatReadError, ValueError, TypeError, OSError, EOFError) as exc:  # EOFError: a file cut short
        raise InputError(str(path), f"is not a MATLAB file ({exc})") from None
    table = _arrays(path, {k: v for k, v in variables.items() if not k.startswith("__")})
    return replace(table, present=tuple(shapes or ()))


def _npz(path: Path) -> Table:
    try:
        with np.load(path, allow_pickle=False) as archive:
            return _arrays(path, {name: archive[name] for name in archive.files})
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as exc:  # EOFError: a file cut short
        raise InputError(str(path), f"is not a NumPy .npz archive ({exc})") from None


def _arrays(path: Path, variables: dict[str, np.ndarray]) -> Table:
    """The variables as columns (vectors of real numbers), constants (1×1) and metadata (text); any other kept in
    ``unread`` with what it is (a struct, a cell, complex numbers, a matrix of its shape)."""
    columns, scalars, meta, unread = {}, {}, {}, {}
    for name, value in variables.items():
        array = np.asarray(value)
        if array.dtype.kind in "US":
            meta[name] = str(array.ravel()[0]) if array.size else ""
        elif array.dtype.kind not in "biufc":
            unread[name] = f"is a {'struct' if array.dtype.names else 'cell or object array'}: a signal is a vector"
        elif array.dtype.kind == "c":
            unread[name] = "holds complex numbers: a signal is real"
        elif array.size == 1:
            scalars[name] = float(array.ravel()[0])
        elif sum(d > 1 for d in array.shape) == 1:
            if array.size > MAX_ROWS:
                raise InputError(f"{path}: {name}", f"has {array.size:,} samples, more than a window may hold")
            columns[name] = array.ravel().astype(np.float64)
        else:
            shape = "×".join(str(d) for d in array.shape)
            unread[name] = f"is a {shape} array: a signal is one vector (n×1 or 1×n)"
    return Table(columns, scalars, meta, unread)


def _json(path: Path) -> Table:
    """A recorder's JSON: an object whose numbers (and true/false, as 1/0) are constants, nested objects' under
    ``outer.inner``, and whose one list of objects holds a sample each, their numbers the columns (a list alone: the
    samples, no constants). A field missing from a sample, or not a number there, leaves its column out as text."""
    document = load_json(path)
    schema = ema_schema(document)
    if schema is not None:
        raise EmaDocumentError(str(path), f"is an {schema} document, not a recorder's log: read it without a log map")
    header: dict[str, object] = {} if isinstance(document, list) else document if isinstance(document, dict) else {}
    lists = {name: value for name, value in header.items() if _samples(value)}
    if isinstance(document, list) and _samples(document):
        lists = {"": document}
    if len(lists) != 1:
        found = ", ".join(lists) or "none"
        raise InputError(str(path), f"is not a recorder's JSON: it needs one list of samples (objects), found {found}")
    (entries,) = lists.values()
    assert isinstance(entries, list)
    if len(entries) > MAX_ROWS:
        raise InputError(str(path), f"has over {MAX_ROWS:,} samples, more than a window may hold: cut it")
    scalars, meta = _header(header)
    columns, unread = {}, {}
    for name in dict.fromkeys(key for entry in entries[:1] for key in entry):
        values = [_json_number(entry.get(name)) for entry in entries]
        if None in values:
            unread[name] = f"is not numeric throughout: sample {values.index(None)} holds no number"
        else:
            columns[name] = np.array(values, dtype=np.float64)
    return Table(columns, scalars, meta, unread)


class EmaDocumentError(InputError):
    """A JSON file given as a recorder's log is one of ema's own documents (a window, or one that goes beside a
    log): its reader may read it as such instead."""


def ema_schema(document: object) -> str | None:
    """The ``ema-…`` schema a parsed JSON document (or the first of a list) names, or None: not one of ema's."""
    first = document[0] if isinstance(document, list) and document else document
    schema = first.get("schema") if isinstance(first, dict) else None
    return schema if isinstance(schema, str) and schema.startswith("ema-") else None


def _samples(value: object) -> bool:
    return isinstance(value, list) and len(value) > 0 and all(isinstance(entry, dict) for entry in value)


def _json_number(value: object) -> float | None:
    """A sample's value as a number: true/false as 1/0, a number itself, else None (text, null, a list)."""
    if isinstance(value, bool):
        return float(value)
    if isinstance(value, int | float) and np.isfinite(value):
        return float(value)
    return None


def _header(header: dict[str, object], prefix: str = "") -> tuple[dict[str, float], dict[str, str]]:
    """The header's numbers as constants and its text as metadata, nested objects' under ``outer.inner``."""
    scalars: dict[str, float] = {}
    meta: dict[str, str] = {}
    for name, value in header.items():
        if isinstance(value, dict):
            inner_scalars, inner_meta = _header(value, f"{prefix}{name}.")
            scalars |= inner_scalars
            meta |= inner_meta
        elif isinstance(value, str):
            meta[prefix + name] = value
        elif (number := _json_number(value)) is not None:
            scalars[prefix + name] = number
    return scalars, meta
