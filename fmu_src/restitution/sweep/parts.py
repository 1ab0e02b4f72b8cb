"""Finished chunks on disk: the part store a sweep writes each chunk to as it completes (and resumes
from), and the result whose table stays there (streamed chunk by chunk when written).

A part file, ``chunk-<start>-<stop>.npz``, holds the chunk's columns and a record of what it is: its
case range, the sweep it belongs to (a fingerprint of the manifest) and the sha256 of its columns.
It is written under a temporary name and renamed (:func:`restitution.output_files.atomic_write`); not
fsynced, since --resume checks it.
On resume every part is checked before it is used: a file that is not a regular file, not a readable
.npz, holds other cases than its name says (two parts swapped), belongs to another sweep, or whose
columns do not match their checksum is removed and its cases are computed again (one line on stderr
each); numpy reads it with ``allow_pickle=False``, and only after every array's header was checked
for the chunk's shape, so nothing is unpickled and no garbage header allocates."""
from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import stat
import sys
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..output_files import OutputWriteError, atomic_write, file_kind, os_reason
from .table import (COLUMNS, VALIDITY, SweepResult, arrow_table, assemble, parquet_options, table_counts,
                    write_csv_rows)

__all__ = ["PartStore", "DiskSweepResult", "ResumeError", "PartError", "part_digest"]

#: A part file's name: its first case and one past its last, 15 digits each.
PART_NAME = re.compile(r"chunk-(\d{15})-(\d{15})\.npz")


class ResumeError(ValueError):
    """``resume=True`` on the finished chunks of another sweep (spec, back end, chunk size or columns),
    or on a damaged part that cannot be removed."""


class PartError(ValueError):
    """A part file that cannot be used (``reason``: one line saying why)."""

    def __init__(self, file, reason: str):
        super().__init__(f"{file}: {reason}")
        self.file, self.reason = Path(file), reason


def _feed(h, col: np.ndarray) -> None:
    """The bytes of ``col`` (as stored: C order) into the hash ``h``, without copying a contiguous
    column or materializing a one-value view (stride 0)."""
    if col.flags.c_contiguous:
        h.update(col.view(np.uint8) if col.size else b"")
    elif col.ndim == 1 and col.strides[0] == 0 and col.size:
        block = np.ascontiguousarray(col[:min(col.size, 8192)]).view(np.uint8)
        whole, rest = divmod(col.size, block.size // col.itemsize)
        for _ in range(whole):
            h.update(block)
        h.update(block[:rest * col.itemsize])
    else:
        h.update(np.ascontiguousarray(col).view(np.uint8))


def part_digest(columns: dict, a: int, b: int, sweep: str) -> str:
    """sha256 of a chunk: its case range, the sweep's fingerprint, and every column's name, type,
    length and bytes (in name order)."""
    h = hashlib.sha256(json.dumps({"range": [int(a), int(b)], "sweep": sweep}).encode())
    for name in sorted(columns):
        col = np.asarray(columns[name]).reshape(-1)
        h.update(f"\0{name}\0{col.dtype.str}\0{col.size}\0".encode())
        _feed(h, col)
    return h.hexdigest()


def _check_headers(file: Path, rows: int) -> None:
    """Every array in the .npz has the chunk's shape (the record: a string) and no Python objects:
    checked from the headers, before numpy allocates anything."""
    with zipfile.ZipFile(file) as zf:
        names = zf.namelist()
        if "info.npy" not in names:
            raise ValueError("no record of its case range and checksum")
        for name in names:
            with zf.open(name) as f:
                version = np.lib.format.read_magic(f)
                read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
                shape, _fortran, dtype = read(f)
            if dtype.hasobject:
                raise ValueError(f"{name} holds Python objects")
            want = () if name == "info.npy" else (rows,)
            if shape != want or (name == "info.npy" and (dtype.kind != "U" or dtype.itemsize > 2**20)):
                raise ValueError(f"{name} has shape {shape} ({dtype}), not {want}")


class PartStore:
    """Finished chunks of one sweep on disk: ``chunk-<start>-<stop>.npz`` and ``manifest.json``.
    ``log``: where the one-line notes on damaged parts go (default: stderr)."""

    def __init__(self, path: Path, log=None):
        self.path = Path(path)
        self.log = log or (lambda text: print(text, file=sys.stderr, flush=True))
        self.sweep = None  #: fingerprint of the sweep opened (sha256 of its manifest)

    def _read_manifest(self):
        """(manifest or None, why it cannot be used or None)."""
        file = self.path / "manifest.json"
        if not os.path.lexists(file):
            return None, None
        try:
            data = json.loads(file.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            return None, f"unreadable ({os_reason(exc)})"
        size = data.get("chunk_size") if isinstance(data, dict) else None
        if not isinstance(size, int) or isinstance(size, bool) or size < 1:
            return None, "not a manifest of finished chunks"
        return data, None

    def manifest(self):
        """The manifest of the chunks here, None if there is none or it cannot be read."""
        return self._read_manifest()[0]

    def file(self, a: int, b: int) -> Path:
        return self.path / f"chunk-{a:015d}-{b:015d}.npz"

    def open(self, spec, backend, chunk_size, keep, resume: bool, load_columns: bool = True,
             on_chunk=None) -> dict:
        """Chunks already finished (``resume``; start -> (columns, info), columns None unless
        ``load_columns``; each chunk's columns shown to ``on_chunk(a, b, columns)`` if given, as they are read), after checking that they belong to this sweep and that each part is
        whole (a damaged one is removed, so its cases are computed again); without ``resume``, an
        empty directory."""
        manifest = json.loads(json.dumps({
            "spec": spec.as_dict(), "backend": backend.name, "chunk_size": int(chunk_size),
            "n_cases": int(spec.n_cases), "columns": None if keep is None else sorted(keep)}))
        self.sweep = hashlib.sha256(json.dumps(manifest, sort_keys=True).encode()).hexdigest()
        self.n_cases, self.chunk_size = int(spec.n_cases), int(chunk_size)
        old = None
        if resume:
            old, problem = self._read_manifest()
            if problem:
                self.log(f"--resume: {self.path / 'manifest.json'}: {problem}: the finished chunks cannot be "
                         f"matched to this sweep; the whole sweep runs")
        if old is not None and old != manifest:
            raise ResumeError(f"--resume: the finished chunks in {self.path} belong to another sweep "
                              f"(spec, back end or columns differ); run without --resume to start over")
        try:
            if old is None and os.path.lexists(self.path):
                shutil.rmtree(self.path)
            self.path.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputWriteError(self.path, exc) from None
        if old is None:
            atomic_write(self.path / "manifest.json",
                         lambda tmp: Path(tmp).write_text(json.dumps(manifest, indent=1), encoding="utf-8"),
                         "manifest")
            return {}
        done = {}
        for file in sorted(self.path.iterdir()):
            name = file.name
            if name.startswith(".chunk-") and ".tmp" in name:  # a killed run's unfinished part
                self._remove(file, None, "an unfinished part")
                continue
            if not name.startswith("chunk-"):
                continue
            match = PART_NAME.fullmatch(name)
            chunk = None  # (a, b) once the name is one of this sweep's chunks
            try:
                if match is None:
                    raise PartError(file, "not a name this sweep gives its parts")
                a, b = int(match[1]), int(match[2])
                if not (a < self.n_cases and a % self.chunk_size == 0 and b == min(a + self.chunk_size, self.n_cases)):
                    raise PartError(file, f"cases {a:,} to {b - 1:,} are not one of this sweep's chunks "
                                          f"({self.chunk_size:,} cases each)")
                chunk = (a, b)
                columns, info = self.read(a, b, checksum=True)
            except PartError as exc:
                self._remove(file, chunk, exc.reason)
                continue
            if on_chunk is not None:  # read for the check anyway: the analyses need no second read
                on_chunk(a, b, columns)
            done[a] = (columns if load_columns else None, info)
        return done

    def _remove(self, file: Path, cases, problem: str) -> None:
        """Remove a part that cannot be used (the name only: a symlink, never its target), and say so."""
        try:
            os.unlink(file)
        except OSError as exc:
            raise ResumeError(f"--resume: {file}: {problem}, and it cannot be removed ({os_reason(exc)}): "
                              f"remove it, or run without --resume") from None
        if problem == "an unfinished part":
            return
        redo = f"its cases {cases[0]:,} to {cases[1] - 1:,} are computed again" if cases else "removed"
        self.log(f"--resume: {file}: {problem}; {redo}")

    def read(self, a: int, b: int, load_columns: bool = True, checksum: bool = False):
        """(columns or None, info) of the chunk of cases ``a`` to ``b - 1``, checked: a regular file, a
        readable .npz of arrays of ``b - a`` rows, its recorded range ``[a, b]``, its ``case`` column
        ``a ... b - 1``; with ``checksum``, its sweep and the sha256 of its columns too. PartError
        (one line) otherwise."""
        file = self.file(a, b)
        try:
            st = os.lstat(file)
        except OSError as exc:
            raise PartError(file, f"cannot be read ({os_reason(exc)})") from None
        if not stat.S_ISREG(st.st_mode):
            kind = "a symlink" if stat.S_ISLNK(st.st_mode) else file_kind(st.st_mode)
            raise PartError(file, f"is {kind}, not a part this sweep wrote")
        try:
            _check_headers(file, b - a)
            with np.load(file, allow_pickle=False) as z:
                info = json.loads(str(z["info"]))
                columns = {k[2:]: z[k] for k in z.files if k.startswith("c:")}
        except Exception as exc:  # noqa: BLE001 - whatever a damaged file raises, it is not a part
            raise PartError(file, f"not a whole part ({type(exc).__name__}: {os_reason(exc)})") from None
        record = info.get("part") if isinstance(info, dict) else None
        if not isinstance(record, dict):
            raise PartError(file, "no record of its case range and checksum")
        if record.get("range") != [a, b]:
            got = record.get("range")
            held = (f"cases {got[0]:,} to {got[1] - 1:,}" if isinstance(got, list) and len(got) == 2
                    and all(isinstance(x, int) for x in got) else f"the range {got!r}")
            raise PartError(file, f"holds {held}, not {a:,} to {b - 1:,} (parts swapped or renamed)")
        case = columns.get("case")
        if case is None or case.dtype.kind not in "iu" or not np.array_equal(case, np.arange(a, b)):
            raise PartError(file, f"its case column is not {a:,} ... {b - 1:,}")
        if checksum:
            if record.get("sweep") != self.sweep:
                raise PartError(file, "belongs to another sweep")
            if record.get("sha256") != part_digest(columns, a, b, self.sweep):
                raise PartError(file, "its columns do not match their checksum (sha256)")
        if not (isinstance(info.get("code"), str) and isinstance(info.get("pid"), int)
                and isinstance(info.get("cpu"), (int, float))):
            raise PartError(file, "its record of how it was computed is incomplete")
        info["counts"] = table_counts(columns)  # from the columns themselves, never as recorded
        return (columns if load_columns else None), info

    def write(self, a: int, b: int, part) -> None:
        """The chunk ``a`` ... ``b - 1`` as a part file, with its range and checksum; written under a
        temporary name and renamed (an I/O error: OutputWriteError naming the part). Not fsynced: --resume
        verifies every part's checksum and computes a bad one again, so a part that a power loss cut
        short is never used, and a streamed run does not wait for the disk chunk by chunk."""
        columns, info = part
        record = {"range": [int(a), int(b)], "sweep": self.sweep, "sha256": part_digest(columns, a, b, self.sweep)}
        text = np.array(json.dumps({**info, "part": record}, default=str))
        atomic_write(self.file(a, b), lambda tmp: np.savez(tmp, info=text, **{f"c:{k}": v for k, v in columns.items()}),
                     "chunk file", durable=False)

    def remove(self) -> None:
        shutil.rmtree(self.path, ignore_errors=True)


@dataclass
class DiskSweepResult(SweepResult):
    """A sweep whose table stays on disk, in its finished chunks (``run_sweep(..., in_memory=False)``):
    the counts are known, :meth:`write` streams the table chunk by chunk; ``columns`` is empty."""

    parts: Path | None = None  #: the directory of the finished chunks
    chunk_counts: dict = field(default_factory=dict)  #: chunk start -> counts

    def __len__(self):
        return sum(c["cases"] for c in self.chunk_counts.values())

    def __getitem__(self, name):
        raise KeyError(f"{name!r}: this sweep's table is on disk ({self.parts}), not in memory; write() it")

    def counts(self) -> dict:
        total = {k: 0 for k in ("cases", "ok", "inside", *VALIDITY)}
        for c in self.chunk_counts.values():
            for k in total:
                total[k] += c[k]
        return total

    def _write_to(self, path: Path, suffix: str) -> None:
        store = PartStore(self.parts)
        keep = self.info.get("keep")
        starts = sorted(self.chunk_counts)

        def chunk(a):  # checked: its range and case column (PartError, one line, otherwise)
            return store.read(a, a + self.chunk_counts[a]["cases"])[0]

        if suffix.lower() == ".parquet":
            import pyarrow.parquet as pq

            writer = None
            try:
                for a in starts:
                    cols = assemble(self.spec, [chunk(a)], keep)
                    table = arrow_table(cols)
                    if writer is None:
                        writer = pq.ParquetWriter(path, table.schema, **parquet_options(cols))
                    writer.write_table(table)
                if writer is None:  # no chunk finished: an empty table with the columns
                    cols = assemble(self.spec, [], keep)
                    pq.write_table(arrow_table(cols), path, **parquet_options(cols))
            finally:
                if writer is not None:
                    writer.close()
            return
        names = [c for c in COLUMNS if keep is None or c in keep]
        with open(path, "w", encoding="utf-8", newline="") as f:
            f.write(",".join(names) + "\n")
            for a in starts:
                write_csv_rows(f, assemble(self.spec, [chunk(a)], keep))

    def to_csv(self, path) -> Path:
        self._write_to(Path(path), ".csv")
        return Path(path)

    def to_parquet(self, path) -> Path:
        self._write_to(Path(path), ".parquet")
        return Path(path)

    def to_pandas(self):
        raise RuntimeError(f"this sweep's table is on disk ({self.parts}), too big for memory; write() it")

    def plot(self, path, **kwargs) -> Path:
        raise RuntimeError("no COR map for a sweep streamed to disk: its table does not fit in memory "
                           "(plot a smaller sweep, or from the written table)")
