"""What the sweep and the scene tools write (restitution.output_files): an output path that exists
and is not a regular file (a character device, a directory, a FIFO, a socket, a symlink to a device)
is refused before any work, one line on stderr, exit 2, and left as it was; an I/O error (ENOSPC,
EIO, EACCES) is one line naming the path and the reason, exit 74, no traceback, nothing half written
under the final name (the old file intact) and the sweep's finished parts kept; --resume over
damaged parts (truncated, garbage, swapped, another range, another sweep, a checksum mismatch, a
part of the earlier .npz format with a pickle inside) computes them again and gives the uninterrupted table, rows in case order.

I/O errors are simulated in this process by failing a system call of restitution.output_files (the
open of the temporary file, a write, an fsync) for one file, and, as root, met for real on a small
tmpfs that fills up."""
import contextlib
import errno
import os
import shutil
import socket
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from restitution import output_files
from restitution.scene.__main__ import main as scene_cli
from restitution.sweep import SweepSpec, read_table, run_sweep
from restitution.sweep.__main__ import main as sweep_cli
from restitution.sweep.parts import RECORD_KEY as RECORD
from scene_texts import steel_on_aluminium

PYTHON = sys.executable
ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}
ENV.pop("DASK_SCHEDULER_ADDRESS", None)

#: 120 cases in 12 chunks of 10, serially: a sweep of a fraction of a second, inside the validated
#: ranges (no warning line on stderr).
SWEEP = ["--pair", "s2_tool_steel/al_6061", "--grid", "v=geomspace:0.1:10:40", "--grid", "t/d=1,3,10",
         "--scheduler", "serial", "--chunk-size", "10", "--no-progress"]
SPEC = dict(pairs=["s2_tool_steel/al_6061"], grid={"v": "geomspace:0.1:10:40", "t/d": "1,3,10"})
N_CASES, N_CHUNKS = 120, 12

SCENE = """
[scene]
name = "io"

[outputs]
requested = ["bounce_heights", "cor"]
tolerance = 1e-2

[simulation]
v_min = "0.05 m/s"
""" + steel_on_aluminium("{heights}")


def scene_file(directory: Path, n_drops: int = 5) -> Path:
    path = directory / "io.toml"
    path.write_text(SCENE.format(heights="[" + ", ".join(f'"{0.05 + 0.01 * k:.2f} m"' for k in range(n_drops)) + "]"))
    return path


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    """The pythonfmu SpherePlateImpact.fmu alone, built from the working tree (seconds)."""
    from restitution.fmu.builders import build_one

    return build_one("SpherePlateImpact", tmp_path_factory.mktemp("fmu"))


@pytest.fixture(scope="module")
def reference():
    """The sweep, uninterrupted, in memory."""
    return run_sweep(SweepSpec(**SPEC), scheduler="serial", chunk_size=10)


def assert_table(columns: dict, reference) -> None:
    """Rows in case order, every column the reference's. Floats to rtol 1e-12: the same function
    evaluates the same inputs on this machine, and a part read back is bit for bit what was written,
    so they agree to the last bit in practice; the tolerance leaves room only for a last-bit
    difference of a SIMD kernel on an array of another length or alignment, while a row out of place
    or from another case differs at O(1e-3) or more (the speeds step by 12 % from row to row)."""
    assert np.array_equal(columns["case"], np.arange(N_CASES))
    assert list(columns) == list(reference.columns)
    for name, ref in reference.columns.items():
        got = np.asarray(columns[name])
        if ref.dtype.kind == "f":
            np.testing.assert_allclose(got, ref, rtol=1e-12, atol=0, equal_nan=True, err_msg=name)
        else:
            assert np.array_equal(got, ref), name


def one_line(err: str, *words) -> str:
    assert "Traceback" not in err, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for w in words:
        assert w in lines[0], (w, lines[0])
    return lines[0]


def no_temporaries(directory: Path) -> None:
    left = [p.name for p in directory.rglob(".*") if ".tmp" in p.name or ".old" in p.name]
    assert not left, left


# --- outputs that are not regular files: refused before any work, left as they were ----------------
KINDS = ("character device", "directory", "FIFO", "socket", "symlink to a device")


def make_special(kind: str, path: Path, keep: list) -> Path:
    """``path`` made into ``kind`` (relative to the current directory: a socket's name is short);
    /dev/null itself for a character device (safe to name as a target)."""
    if kind == "character device":
        return Path("/dev/null")
    if kind == "directory":
        path.mkdir()
    elif kind == "FIFO":
        os.mkfifo(path)
    elif kind == "socket":
        sock = socket.socket(socket.AF_UNIX)
        sock.bind(str(path))
        keep.append(sock)
    else:
        path.symlink_to("/dev/null")
    return path


def assert_still(kind: str, path: Path) -> None:
    mode = os.stat(path).st_mode  # follows a symlink to its device
    test = {"character device": stat.S_ISCHR, "directory": stat.S_ISDIR, "FIFO": stat.S_ISFIFO,
            "socket": stat.S_ISSOCK, "symlink to a device": stat.S_ISCHR}[kind]
    assert test(mode), (kind, oct(mode))
    if kind == "symlink to a device":
        assert path.is_symlink() and os.readlink(path) == "/dev/null"
    if kind == "character device":
        assert os.stat("/dev/null").st_rdev == os.makedev(1, 3)


WORDS = {"character device": "a character device", "directory": "a directory", "FIFO": "a FIFO",
         "socket": "a socket", "symlink to a device": "a symlink to /dev/null"}


@pytest.mark.parametrize("option", ["--out", "--plot"])
@pytest.mark.parametrize("kind", KINDS)
def test_sweep_refuses_an_output_that_is_not_a_regular_file(kind, option, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    keep = []
    target = make_special(kind, Path("x.csv" if option == "--out" else "x.png"), keep)
    args = ["--out", str(target)] if option == "--out" else ["--out", "s.csv", "--plot", str(target)]
    status = sweep_cli([*SWEEP, *args])
    line = one_line(capsys.readouterr().err, option, str(target), WORDS[kind], "not a regular file")
    assert status == 2, line
    assert_still(kind, target)
    assert sorted(p.name for p in tmp_path.iterdir()) == ([] if target.is_absolute() else [target.name])
    assert not os.path.lexists("/dev/null.parts")
    for sock in keep:
        sock.close()


@pytest.mark.parametrize("kind", KINDS)
def test_scene_refuses_an_output_that_is_not_a_regular_file(kind, tmp_path, monkeypatch, capsys):
    """No FMU is needed: the outputs are checked before the FMU is looked for."""
    monkeypatch.chdir(tmp_path)
    scene = scene_file(tmp_path)
    keep = []
    (tmp_path / "out").mkdir()
    special = make_special(kind, Path("out/io_summary.csv"), keep) if kind != "character device" else None
    if special is not None:  # `run`: one of the files it writes, in its --out directory
        assert scene_cli(["run", str(scene), "--out", "out", "--no-progress"]) == 2
        one_line(capsys.readouterr().err, str(special), WORDS[kind], "not a regular file")
        assert_still(kind, special)
        assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["io_summary.csv"]
    target = make_special(kind, Path("r.md"), keep)  # `report --out FILE`
    assert scene_cli(["report", str(scene), "--out", str(target), "--no-progress"]) == 2
    one_line(capsys.readouterr().err, "--out", str(target), WORDS[kind], "not a regular file")
    assert_still(kind, target)
    assert scene_cli(["run", str(scene), "--out", "/dev/null", "--no-progress"]) == 2  # run --out DIR
    one_line(capsys.readouterr().err, "--out /dev/null", "a character device, not a directory")
    assert_still("character device", Path("/dev/null"))
    for sock in keep:
        sock.close()


def test_a_symlink_to_a_regular_file_writes_its_target(tmp_path, reference, capsys):
    real = tmp_path / "real.csv"
    real.write_text("old\n")
    (tmp_path / "link.csv").symlink_to(real)
    assert sweep_cli([*SWEEP, "--no-plot", "--out", str(tmp_path / "link.csv")]) == 0
    assert (tmp_path / "link.csv").is_symlink()
    assert_table(read_table(real), reference)
    no_temporaries(tmp_path)


# --- I/O errors, simulated: one system call of restitution.output_files fails --------------------
class FailingOs:
    """``os`` for restitution.output_files, whose ``call`` ("open", "write", "fsync") fails with
    ``code`` on the file whose name ``match`` accepts (the temporary file of an output is
    ``.<stem>.<pid>-<n>.tmp<suffix>``), from its ``after``-th such call on."""

    def __init__(self, call: str, code: int, match, after: int = 0):
        self.call, self.code, self.match, self.after, self.calls = call, code, match, after, 0

    def __getattr__(self, name):
        real = getattr(os, name)
        if name != self.call:
            return real

        def failing(*args, **kwargs):
            target = args[0]
            path = os.readlink(f"/proc/self/fd/{target}") if isinstance(target, int) else os.fspath(target)
            if self.match(Path(path).name):
                self.calls += 1
                if self.calls > self.after:
                    raise OSError(self.code, os.strerror(self.code), None if isinstance(target, int) else path)
            return real(*args, **kwargs)
        return failing


def temporary_of(name: str):
    stem, suffix = os.path.splitext(name)
    return lambda base: base.startswith(f".{stem}.") and base.endswith(f".tmp{suffix}")


CODES = {errno.ENOSPC: ("fsync", "No space left on device (ENOSPC)"), errno.EIO: ("fsync", "Input/output error (EIO)"),
         errno.EACCES: ("open", "Permission denied (EACCES)")}


@pytest.mark.parametrize("code", sorted(CODES))
def test_sweep_table_io_error_keeps_the_old_table_and_every_part(code, tmp_path, reference, monkeypatch, capsys):
    out = tmp_path / "s.csv"
    out.write_text("the old table\n")
    call, reason = CODES[code]
    monkeypatch.setattr(output_files, "os", FailingOs(call, code, temporary_of("s.csv")))
    assert sweep_cli([*SWEEP, "--no-plot", "--out", str(out)]) == output_files.EXIT_IO_ERROR
    one_line(capsys.readouterr().err, f"cannot write {out}: {reason}", "every chunk is kept", "--resume")
    assert out.read_text() == "the old table\n"
    assert len(list((tmp_path / "s.csv.parts" / "package").glob("chunk-*.parquet"))) == N_CHUNKS
    no_temporaries(tmp_path)
    monkeypatch.undo()
    assert sweep_cli([*SWEEP, "--no-plot", "--out", str(out), "--resume"]) == 0
    assert_table(read_table(out), reference)
    assert not (tmp_path / "s.csv.parts").exists()


@pytest.mark.parametrize("code", sorted(CODES))
def test_sweep_part_io_error_keeps_the_finished_parts_for_resume(code, tmp_path, reference, monkeypatch, capsys):
    out = tmp_path / "s.csv"
    call, reason = CODES[code]
    call = "replace" if call == "fsync" else call  # parts are not fsynced (--resume checks them): fail the rename
    part = "chunk-000000000000050-000000000000060.parquet"
    monkeypatch.setattr(output_files, "os", FailingOs(call, code, temporary_of(part)))
    assert sweep_cli([*SWEEP, "--no-plot", "--out", str(out)]) == output_files.EXIT_IO_ERROR
    one_line(capsys.readouterr().err, f"{part}: {reason}", "the 5 finished chunk(s) are kept", "--resume")
    assert not out.exists()
    parts = tmp_path / "s.csv.parts" / "package"
    assert sorted(p.name for p in parts.iterdir()) == [
        f"chunk-{a:015d}-{a + 10:015d}.parquet" for a in range(0, 50, 10)] + ["manifest.json"]
    monkeypatch.undo()
    assert sweep_cli([*SWEEP, "--no-plot", "--out", str(out), "--resume"]) == 0
    assert capsys.readouterr().err.count("--resume") == 0  # the kept parts were whole: nothing to say
    assert_table(read_table(out), reference)


def test_sweep_cor_map_io_error_is_one_line_after_the_table(tmp_path, reference, monkeypatch, capsys):
    monkeypatch.setattr(output_files, "os", FailingOs("fsync", errno.ENOSPC, temporary_of("s_cor_map.png")))
    assert sweep_cli([*SWEEP, "--out", str(tmp_path / "s.csv")]) == output_files.EXIT_IO_ERROR
    one_line(capsys.readouterr().err, "s_cor_map.png: No space left on device", "the table was written")
    assert_table(read_table(tmp_path / "s.csv"), reference)
    assert not (tmp_path / "s_cor_map.png").exists()
    no_temporaries(tmp_path)


def growing_csv(name):  # the scene's CSV: its temporary file, then the file under its name
    return lambda base: base == name or temporary_of(name)(base)


@pytest.mark.parametrize("old", [None, "the old rows\n"], ids=["new", "old file"])
@pytest.mark.parametrize("code, call, after", [(errno.ENOSPC, "write", 3), (errno.EIO, "fsync", 1),
                                               (errno.EACCES, "open", 0)])
def test_scene_io_error_leaves_nothing_half_written(code, call, after, old, fmu, tmp_path, monkeypatch, capsys):
    """``after``: the calls that succeed first (the header and two drops' writes; one drop's fsync)."""
    scene = scene_file(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    for name in ("io.csv", "io_summary.csv"):
        if old:
            (out / name).write_text(old)
    monkeypatch.setattr(output_files, "os", FailingOs(call, code, growing_csv("io.csv"), after))
    status = scene_cli(["run", str(scene), "--fmu", str(fmu), "--out", str(out), "--no-progress", "--no-plot"])
    one_line(capsys.readouterr().err, f"cannot write {out / 'io.csv'}: {os.strerror(code)}")
    assert status == output_files.EXIT_IO_ERROR
    if old:
        assert {p.name: p.read_text() for p in out.iterdir()} == {"io.csv": old, "io_summary.csv": old}
    else:
        assert list(out.iterdir()) == []
    monkeypatch.undo()
    assert scene_cli(["run", str(scene), "--fmu", str(fmu), "--out", str(out), "--no-progress", "--no-plot"]) == 0
    assert (out / "io.csv").read_text().count("\n") > 5
    no_temporaries(tmp_path)


def test_scene_summary_io_error_puts_both_old_files_back(fmu, tmp_path, monkeypatch, capsys):
    scene = scene_file(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    for name in ("io.csv", "io_summary.csv"):
        (out / name).write_text(f"old {name}\n")
    monkeypatch.setattr(output_files, "os", FailingOs("fsync", errno.ENOSPC, temporary_of("io_summary.csv")))
    assert scene_cli(["run", str(scene), "--fmu", str(fmu), "--out", str(out), "--no-progress"]) == 74
    one_line(capsys.readouterr().err, f"cannot write {out / 'io_summary.csv'}: No space left on device")
    assert {p.name: p.read_text() for p in out.iterdir()} == {n: f"old {n}\n" for n in ("io.csv", "io_summary.csv")}


# --- I/O errors for real: a small tmpfs that fills up (root only) -----------------------------------
@contextlib.contextmanager
def full_disk(where: Path, size: str):
    if os.geteuid() != 0:
        pytest.skip("a real full file system needs root here (mount -t tmpfs)")
    where.mkdir()
    proc = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(where)], capture_output=True,
                          text=True)
    if proc.returncode != 0:
        pytest.skip(f"mount -t tmpfs is not permitted here: {proc.stderr.strip()}")
    try:
        yield where
    finally:
        subprocess.run(["umount", str(where)], check=False)


def child(*args, cwd):
    return subprocess.run([PYTHON, "-m", *args], capture_output=True, text=True, cwd=cwd, env=ENV, timeout=300)


def test_sweep_on_a_full_file_system(tmp_path, reference):
    """Parts fill 256 KiB after a few chunks: one line naming the part, the finished ones kept; with
    the space back, --resume completes the table; a table that does not fit leaves the old one."""
    # 12 parts of about 16 kB (20 kB in tmpfs pages) and a CSV of about 60 kB fit in 384 kB; with 278 kB of
    # ballast the parts fill the disk after a few chunks
    with full_disk(tmp_path / "disk", "384k") as disk:
        (disk / "ballast").write_bytes(b"\0" * (278 * 1024))
        (disk / "s.csv").write_text("the old table\n")
        proc = child("restitution.sweep", *SWEEP, "--no-plot", "--out", "s.csv", cwd=disk)
        assert proc.returncode == 74, proc.stderr
        one_line(proc.stderr, "cannot write s.csv.parts/package/chunk-", "No space left on device (ENOSPC)",
                 "finished chunk(s) are kept in s.csv.parts", "--resume")
        kept = sorted((disk / "s.csv.parts" / "package").glob("chunk-*.parquet"))
        assert 0 < len(kept) < N_CHUNKS
        assert (disk / "s.csv").read_text() == "the old table\n"
        no_temporaries(disk)
        (disk / "ballast").unlink()
        proc = child("restitution.sweep", *SWEEP, "--no-plot", "--out", "s.csv", "--resume", cwd=disk)
        assert proc.returncode == 0, proc.stderr
        assert_table(read_table(disk / "s.csv"), reference)
        # every part whole on the disk, and less room left than the table takes: --resume only writes it
        parts = disk / "s.csv.parts" / "package"
        run_sweep(SweepSpec(**SPEC), scheduler="serial", chunk_size=10, parts=parts)
        (disk / "s.csv").write_text("the old table\n")
        free = os.statvfs(disk).f_bavail * os.statvfs(disk).f_frsize
        (disk / "ballast").write_bytes(b"\0" * (free - 16 * 1024))  # the CSV takes about 60 kB
        proc = child("restitution.sweep", *SWEEP, "--no-plot", "--out", "s.csv", "--resume", cwd=disk)
        assert proc.returncode == 74, proc.stderr
        one_line(proc.stderr, "cannot write s.csv: No space left on device", "every chunk is kept in s.csv.parts")
        assert (disk / "s.csv").read_text() == "the old table\n"
        assert len(list(parts.glob("chunk-*.parquet"))) == N_CHUNKS
        no_temporaries(disk)


def test_scene_on_a_full_file_system(fmu, tmp_path):
    scene = scene_file(tmp_path, n_drops=100)  # 500 impacts: a CSV of about 65 kB
    with full_disk(tmp_path / "disk", "24k") as disk:
        for old in (None, "the old rows\n"):
            if old:
                for name in ("io.csv", "io_summary.csv"):
                    (disk / name).write_text(old)
            proc = child("restitution.scene", "run", str(scene), "--fmu", str(fmu), "--out", str(disk), "--no-plot",
                         "--no-progress", cwd=tmp_path)
            assert proc.returncode == 74, proc.stderr
            one_line(proc.stderr, f"cannot write {disk / 'io.csv'}: No space left on device (ENOSPC)")
            assert {p.name: p.read_text() for p in disk.iterdir()} == (
                {"io.csv": old, "io_summary.csv": old} if old else {})


# --- --resume over damaged parts ------------------------------------------------------------------
class Pickled:
    """Unpickling this creates the file ``marker``: it must never happen."""

    def __init__(self, marker):
        self.marker = marker

    def __reduce__(self):
        return (Path.touch, (Path(self.marker),))


def damage(parts: Path, other_sweep: Path, marker: Path) -> dict:
    """Damage most parts in a different way each; the reason each is expected to be named by."""
    files = sorted(parts.glob("chunk-*.parquet"))
    f = {k: files[k] for k in range(len(files))}
    why = {}
    swap(f[0], f[1])
    why[f[0]] = why[f[1]] = "parts swapped or renamed"
    f[2].write_bytes(f[2].read_bytes()[:1000])  # truncated
    why[f[2]] = "not a whole part"
    f[3].write_bytes(os.urandom(4000))  # garbage
    why[f[3]] = "not a whole part"
    import pyarrow.compute as pc
    import pyarrow.parquet as pq

    record = {RECORD: pq.read_metadata(f[4]).metadata[RECORD]}
    table = pq.read_table(f[4])  # a valid Parquet part, its record kept, whose numbers changed: the checksum
    table = table.set_column(table.column_names.index("e"), "e", pc.add(table.column("e"), 1e-9))
    pq.write_table(table.replace_schema_metadata(record), f[4])
    why[f[4]] = "checksum"
    shutil.copy(next(other_sweep.glob(f"{f[5].name}")), f[5])  # the same range of another sweep
    why[f[5]] = "another sweep"
    # a part of the earlier format (.npz) under this one's name, an object array (a pickle) inside
    with open(f[6], "wb") as out:
        np.savez(out, **{"c:e": np.array([Pickled(marker)] * 10, dtype=object)})
    why[f[6]] = "not a whole part"
    f[7].unlink()
    os.mkfifo(f[7])  # a FIFO in a part's place: never opened
    why[f[7]] = "FIFO"
    bogus = parts / "chunk-000000000000005-000000000000015.parquet"  # not one of the sweep's chunks
    shutil.copy(f[8], bogus)
    why[bogus] = "not one of this sweep's chunks"
    # a Parquet file of the same columns, no record of its range and checksum
    pq.write_table(pq.read_table(f[9]).replace_schema_metadata(None), f[9])
    why[f[9]] = "no record"
    return why


def swap(a: Path, b: Path) -> None:
    """Two parts swapped: each under the other's name."""
    os.replace(a, a.with_name("swap"))
    os.replace(b, a)
    os.replace(a.with_name("swap"), b)


def test_resume_recomputes_damaged_parts_and_keeps_case_order(tmp_path, reference, capsys):
    spec = SweepSpec(**SPEC)
    parts, other = tmp_path / "p", tmp_path / "other"
    run_sweep(spec, scheduler="serial", chunk_size=10, parts=parts)
    run_sweep(SweepSpec(**SPEC, fixed={"effect_tolerance": 0.5}), scheduler="serial", chunk_size=10, parts=other)
    marker = tmp_path / "unpickled"
    why = damage(parts, other, marker)
    capsys.readouterr()
    resumed = run_sweep(spec, scheduler="serial", chunk_size=3, parts=parts, resume=True)  # the parts' 10 is kept
    assert resumed.n_chunks == N_CHUNKS
    assert_table(resumed.columns, reference)
    assert not marker.exists()  # nothing was unpickled
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == len(why), lines
    for file, reason in why.items():
        line, = [x for x in lines if f"{file}:" in x]
        assert line.startswith("--resume: ") and reason in line, (reason, line)
        assert ("computed again" in line) if file.name != "chunk-000000000000005-000000000000015.parquet" else "removed" in line
    assert sorted(p.name for p in parts.glob("chunk-*.parquet")) == [f"chunk-{a:015d}-{a + 10:015d}.parquet"
                                                                for a in range(0, N_CASES, 10)]


def test_cli_resume_over_swapped_parts_writes_rows_in_case_order(tmp_path, reference, capsys):
    out = tmp_path / "s.csv"
    parts = tmp_path / "s.csv.parts" / "package"
    run_sweep(SweepSpec(**SPEC), scheduler="serial", chunk_size=10, parts=parts)
    swap(parts / "chunk-000000000000030-000000000000040.parquet", parts / "chunk-000000000000070-000000000000080.parquet")
    assert sweep_cli([*SWEEP, "--no-plot", "--out", str(out), "--resume"]) == 0
    lines = capsys.readouterr().err.strip().splitlines()
    assert len([x for x in lines if "parts swapped or renamed" in x]) == 2, lines
    assert_table(read_table(out), reference)


def test_resume_over_a_part_that_cannot_be_removed_is_one_line_error(tmp_path, capsys):
    out = tmp_path / "s.csv"
    parts = tmp_path / "s.csv.parts" / "package"
    run_sweep(SweepSpec(**SPEC), scheduler="serial", chunk_size=10, parts=parts)
    part = parts / "chunk-000000000000020-000000000000030.parquet"
    part.unlink()
    part.mkdir()  # a directory in a part's place
    (part / "keep").write_text("not ours")
    assert sweep_cli([*SWEEP, "--no-plot", "--out", str(out), "--resume"]) == 2
    one_line(capsys.readouterr().err, str(part), "is a directory", "cannot be removed", "run without --resume")
    assert (part / "keep").read_text() == "not ours" and not out.exists()


def test_resume_over_an_unreadable_manifest_says_so_and_runs_everything(tmp_path, reference, capsys):
    out = tmp_path / "s.csv"
    parts = tmp_path / "s.csv.parts" / "package"
    run_sweep(SweepSpec(**SPEC), scheduler="serial", chunk_size=10, parts=parts)
    (parts / "manifest.json").write_text('{"chunk_size": "ten"')
    assert sweep_cli([*SWEEP, "--no-plot", "--out", str(out), "--resume"]) == 0
    one_line(capsys.readouterr().err, "manifest.json: unreadable", "the whole sweep runs")  # and nothing else
    assert_table(read_table(out), reference)


def test_check_outputs_refuses_an_output_that_is_an_input_or_another_output(tmp_path):
    """The same file by its name, another spelling (``..``), a symlink or a hard link: refused, one line
    naming both; distinct files, and outputs not given (None), pass."""
    data = tmp_path / "data.csv"
    data.write_text("t_impact\n1\n2\n3\n")
    (tmp_path / "link.json").symlink_to("data.csv")
    os.link(data, tmp_path / "hard.json")
    (tmp_path / "sub").mkdir()
    inputs = {"DATA": data}
    output_files.check_outputs({"--json": tmp_path / "r.json", "--plot": tmp_path / "r.png", "--times": None}, inputs)
    output_files.check_outputs({"--json": None}, {"DATA": None})
    for path in (data, tmp_path / "sub" / ".." / "data.csv", tmp_path / "link.json", tmp_path / "hard.json"):
        with pytest.raises(output_files.OutputPathError) as caught:
            output_files.check_outputs({"--plot": tmp_path / "r.png", "--json": path}, inputs)
        message = str(caught.value)
        assert message.startswith(f"--json {path}: is the input DATA ({data})") and "\n" not in message
    for other in (tmp_path / "r.json", tmp_path / "sub" / ".." / "r.json"):  # not existing yet: by resolved path
        with pytest.raises(output_files.OutputPathError, match=r"--times .*: is the same file as --json"):
            output_files.check_outputs({"--json": tmp_path / "r.json", "--times": other}, inputs)
    assert data.read_text() == "t_impact\n1\n2\n3\n"
