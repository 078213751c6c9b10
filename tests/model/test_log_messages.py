"""A log that does not match its map is refused saying why: the shape found against the shape wanted, the near-miss
name where only the case differs, the time variable where it holds no number, the file's name where it is no id."""

import numpy as np
import pytest
from scipy.io import savemat

from ema.model.checks import InputError
from ema.model.logmap import read_logmap, read_mapped

EMPS_MAP = "examples/emps/log-map.json"


def emps_like(path, **replaced):
    t = np.arange(2000) * 1e-3
    variables = {"t": t, "qg": np.sin(t), "qm": np.sin(t) * 0.99, "vir": np.cos(t), "gtau": 35.15, "kp": 160.0,
                 "kv": 243.0}  # fmt: skip
    variables.update(replaced)
    savemat(path, variables)
    return path


@pytest.mark.parametrize(
    ("replaced", "said"),
    [
        ({"qm": np.zeros((3, 2000))}, "is a 3×2000 array: a signal is one vector"),
        ({"qm": np.sin(np.arange(2000)) * (1 + 1j)}, "holds complex numbers"),
        ({"qm": {"a": 1.0}}, "is a struct"),
        ({"qm": np.array([np.zeros(3), np.zeros(4)], dtype=object)}, "cell or object array"),
    ],
)
def test_a_variable_that_is_no_vector_is_named_with_what_it_is(tmp_path, replaced, said):
    with pytest.raises(InputError, match=said) as refused:
        read_mapped(emps_like(tmp_path / "run.mat", **replaced), read_logmap(EMPS_MAP))
    assert refused.value.field.endswith(": qm")


def test_a_name_that_differs_in_case_is_named(tmp_path):
    path = tmp_path / "run.mat"
    t = np.arange(2000) * 1e-3
    savemat(path, {"t": t, "qg": np.sin(t), "QM": np.sin(t), "vir": np.cos(t), "gtau": 35.15, "kp": 160.0, "kv": 243.0})
    with pytest.raises(InputError, match="has no variable 'qm', but 'QM': names differ in case"):
        read_mapped(path, read_logmap(EMPS_MAP))


def test_nan_in_the_time_variable_is_named_there(tmp_path):
    t = np.arange(2000) * 1e-3
    t[700] = np.nan
    with pytest.raises(InputError, match="time variable holds nan at sample 700") as refused:
        read_mapped(emps_like(tmp_path / "run.mat", t=t), read_logmap(EMPS_MAP))
    assert refused.value.field.endswith(": t")


def test_a_file_whose_name_is_no_id_is_named_with_its_name(tmp_path):
    with pytest.raises(InputError, match=r"its name 'essai_\\\\xe9' is no window id.*rename the file"):
        read_mapped(emps_like(tmp_path / "essai_é.mat"), read_logmap(EMPS_MAP))


def compressed_zeros(path, name: str, rows: int, columns: int, other: dict) -> None:
    """A MATLAB v5 file whose variable ``name`` is a rows×columns array of zeros, compressed as MATLAB does, streamed
    (never allocated here); ``other`` saved beside it by scipy."""
    import struct
    import zlib

    savemat(path, other)
    nbytes = rows * columns * 8
    body = (
        struct.pack("<II", 6, 8) + struct.pack("<II", 6, 0)  # array flags: a double array
        + struct.pack("<II", 5, 8) + struct.pack("<ii", rows, columns)  # dimensions
        + struct.pack("<HH", 1, len(name)) + name.encode().ljust(4, b"\0")  # its name, small format
        + struct.pack("<II", 9, nbytes)  # the real part: miDOUBLE
    )  # fmt: skip
    packer = zlib.compressobj()
    stream = packer.compress(struct.pack("<II", 14, len(body) + nbytes) + body)
    chunk = bytes(2**20)
    for _ in range(nbytes // len(chunk)):
        stream += packer.compress(chunk)
    stream += packer.compress(bytes(nbytes % len(chunk))) + packer.flush()
    with open(path, "ab") as handle:
        handle.write(struct.pack("<II", 15, len(stream)) + stream)


def test_a_small_compressed_file_of_a_huge_array_is_refused_before_it_is_inflated(tmp_path):
    """A file of a few hundred kB holding 4×5,000,000 zeros: refused from the variable's header, its 160 MB never
    inflated."""
    import resource

    path = tmp_path / "bomb.mat"
    t = np.arange(2000) * 1e-3
    compressed_zeros(
        path, "qm", 4, 5_000_000, {"t": t, "qg": np.sin(t), "vir": np.cos(t), "gtau": 1.0, "kp": 1.0, "kv": 1.0}
    )
    assert path.stat().st_size < 2**20
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(InputError, match="4×5,000,000 array, more than a window may hold") as refused:
        read_mapped(path, read_logmap(EMPS_MAP))
    assert refused.value.field.endswith(": qm")
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100 * 1024  # kB: far under its 160 MB
