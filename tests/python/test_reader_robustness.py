"""No input file crashes a reader: bad indices, index pointers, counts and declared sizes in an
FCLib file, corrupted HDF5 and Siconos text files are refused with a coulomb error naming the
file, before scipy or any large allocation sees them (scipy's CSC -> CSR conversion reads out
of bounds on a bad row index, which used to end the process with SIGSEGV). The mutation loops
below run in a child process, so that a crash fails the test with its signal instead of
killing pytest."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from coulomb import errors
from coulomb.io import read_fclib, read_siconos_lcp

h5py = pytest.importorskip("h5py", reason="h5py (the extra coulomb[hdf5]) is not installed")
pytest.importorskip("scipy.sparse")

# the seed's 2D problem (m = 2, one contact) as a local FCLib problem, W in CSC storage
W_CSC = {"nz": -1, "m": 2, "n": 2, "p": [0, 1, 2], "i": [0, 1], "x": [0.5, 0.5]}


def write_fclib(path: Path, w: dict, q=(-3.0, 1.0), mu=(0.2,), dim=2) -> Path:
    with h5py.File(path, "w") as f:
        g = f.create_group("fclib_local")
        g["spacedim"] = np.array([dim])
        wg = g.create_group("W")
        for key, val in w.items():
            wg[key] = np.atleast_1d(np.asarray(val))
        v = g.create_group("vectors")
        v["q"] = np.asarray(q, dtype=float)
        v["mu"] = np.asarray(mu, dtype=float)
    return path


def test_the_well_formed_file_is_read(tmp_path):
    p = read_fclib(write_fclib(tmp_path / "ok.hdf5", W_CSC))
    assert np.array_equal(p.W.toarray(), np.eye(2) / 2) and p.mu.tolist() == [0.2]


BAD_W = {
    "row index too large (CSC)": {**W_CSC, "i": [0, 7]},
    "negative row index (CSC)": {**W_CSC, "i": [-1, 1]},
    "huge row index (CSC)": {**W_CSC, "i": [0, 2**40]},
    "index pointers decrease": {**W_CSC, "p": [0, 2, 1]},
    "index pointers past the indices": {**W_CSC, "p": [0, 1, 9]},
    "index pointers not starting at 0": {**W_CSC, "p": [1, 1, 2]},
    "too few index pointers": {**W_CSC, "p": [0, 2]},
    "column index too large (CSR)": {**W_CSC, "nz": -2, "i": [0, 5]},
    "triplet row out of range": {"nz": 2, "m": 2, "n": 2, "p": [0, 1], "i": [0, 3],
                                 "x": [0.5, 0.5]},
    "triplet negative column": {"nz": 2, "m": 2, "n": 2, "p": [0, -1], "i": [0, 1],
                                "x": [0.5, 0.5]},
    "triplet count beyond the arrays": {"nz": 5, "m": 2, "n": 2, "p": [0, 1], "i": [0, 1],
                                        "x": [0.5, 0.5]},
    "negative size": {**W_CSC, "m": -2},
    "unknown storage": {**W_CSC, "nz": -7},
    "values fewer than entries": {**W_CSC, "x": [0.5]},
}


@pytest.mark.parametrize("case", BAD_W)
def test_bad_matrix_structure_is_a_format_error_naming_the_file(tmp_path, case):
    path = write_fclib(tmp_path / "bad.hdf5", BAD_W[case])
    with pytest.raises(errors.ProblemFormatError) as info:
        read_fclib(path)
    assert str(path) in str(info.value)


def test_a_declared_size_of_1e12_is_refused_before_allocating(tmp_path):
    path = write_fclib(tmp_path / "huge.hdf5",
                       {"nz": 2, "m": 10**12, "n": 10**12, "p": [0, 1], "i": [0, 1],
                        "x": [0.5, 0.5]})
    with pytest.raises(errors.ProblemTooLargeError, match="budget"):
        read_fclib(path)


def test_a_corrupted_hdf5_file_is_a_format_error(tmp_path):
    good = write_fclib(tmp_path / "good.hdf5", W_CSC).read_bytes()
    # zero a stretch in the middle (object headers and B-tree nodes live there)
    path = tmp_path / "corrupt.hdf5"
    mid = len(good) // 2
    path.write_bytes(good[:mid] + bytes(512) + good[mid + 512:])
    try:
        read_fclib(path)
    except errors.CoulombError as exc:
        assert str(path) in str(exc)


FUZZ = textwrap.dedent(
    """
    import random, sys
    from pathlib import Path
    from coulomb import errors
    from coulomb.io import read_fclib, read_siconos_fc, read_siconos_lcp
    src, reader, rounds, out = Path(sys.argv[1]), sys.argv[2], int(sys.argv[3]), sys.argv[4]
    read = {"fclib": read_fclib, "fc": read_siconos_fc, "lcp": read_siconos_lcp}[reader]
    data = src.read_bytes()
    rng = random.Random(12345)
    kinds = {}
    for k in range(rounds):
        b = bytearray(data)
        for _ in range(rng.randint(1, 8)):
            if not b:
                break
            pos = rng.randrange(len(b))
            op = rng.random()
            if op < 0.5:
                b[pos] = rng.randrange(256)
            elif op < 0.7 and reader != "fclib":
                b[pos:pos] = rng.choice([b"-", b"9", b"99999999999", b" ", b"\\n", b"e300"])
            elif op < 0.75:
                del b[pos:pos + rng.randint(1, 16)]
            elif op < 0.85:
                b[pos:pos + 64] = bytes(len(b[pos:pos + 64]))  # a zeroed block
            else:
                b[pos:pos + 4] = rng.randbytes(4)
        path = Path(out)
        path.write_bytes(bytes(b))
        try:
            read(path)
            kinds["read"] = kinds.get("read", 0) + 1
        except errors.CoulombError as exc:
            kinds[type(exc).__name__] = kinds.get(type(exc).__name__, 0) + 1
    print(kinds)
    """
)


def fuzz(src: Path, reader: str, tmp_path: Path, rounds: int) -> str:
    """Runs `rounds` byte mutations of `src` through the reader in a child process; any
    exception that is not a coulomb error, or a crash, fails."""
    out = subprocess.run(
        [sys.executable, "-c", FUZZ, str(src), reader, str(rounds), str(tmp_path / "m.bin")],
        capture_output=True, text=True, timeout=600,
    )
    assert out.returncode == 0, (
        f"reader {reader} crashed or raised a non-coulomb error (return code "
        f"{out.returncode}):\n{out.stderr[-3000:]}"
    )
    return out.stdout


def test_fuzzed_fclib_files_never_crash(tmp_path):
    src = write_fclib(tmp_path / "src.hdf5", W_CSC)
    print(fuzz(src, "fclib", tmp_path, 400))


SICONOS_LCP = "3\n0\n2\n2\n2 2\n1 0 0 1\n-1 -1\n"


def test_fuzzed_siconos_lcp_files_never_crash(tmp_path):
    src = tmp_path / "lcp.dat"
    src.write_text(SICONOS_LCP)
    print(fuzz(src, "lcp", tmp_path, 400))


def test_fuzzed_siconos_fc_files_never_crash(tmp_path, data_dir):
    files = sorted((data_dir / "siconos-fc").glob("*.dat"), key=lambda p: p.stat().st_size)
    if not files:
        pytest.skip("no Siconos friction-contact file to mutate")
    print(fuzz(files[0], "fc", tmp_path, 400))


@pytest.mark.parametrize(
    "text",
    [
        "3\n0\n2\n2\n1000000000000 1000000000000\n1 0 0 1\n-1 -1\n",  # declared 1e12 x 1e12
        "3\n0\n-2\n2\n2 2\n1 0 0 1\n-1 -1\n",
        "3\n0\n99999999999999999999999\n",
    ],
)
def test_siconos_lcp_declared_sizes_are_checked(tmp_path, text):
    path = tmp_path / "bad.dat"
    path.write_text(text)
    with pytest.raises(errors.CoulombError):
        read_siconos_lcp(path)
