"""Finished chunks on disk: the part store a sweep writes each chunk to as it completes (and resumes
from), and writing a table from them (the result whose table stays there is
:class:`restitution.sweep.result.DiskSweepResult`).

Every finished chunk is one Parquet file, ``chunk-<start>-<stop>.parquet``: the chunk's columns as
one row group, encoded once, when the chunk finishes. Its footer carries a record of what it is (key
``restitution.part``): its case range, the sweep it belongs to (a fingerprint of the manifest), the
CRC-32 of its column chunks (the bytes between the footer and the leading magic) and how it was
computed. It is written under a temporary name and renamed (:func:`restitution.output_files.atomic_write`):
a part is either whole or absent, and a killed run loses only the chunks that were being computed. Not
fsynced: --resume checks every part, so one a power loss cut short is computed again.

Why a file per chunk, not row groups appended to one file: a Parquet file is readable only once its
footer is written, so a single growing file would have to be closed (and a new one begun) to make
finished chunks safe, and a crash would lose the open one's chunks. A file per chunk is safe the
moment it is renamed, and costs a footer (a few kB) and a rename per chunk. The written table is
then made without decoding anything: :func:`restitution.sweep.parquet_join.join_parquet` copies
every part's column chunks (in the kernel: ``copy_file_range``) into one file in case order and
writes one footer for all of them. CSV is formatted from the parts, chunk by chunk.

On resume every part is checked before it is used: a file that is not a regular file, not a readable
Parquet file, holds other cases than its name says (two parts swapped), belongs to another sweep,
holds other columns, or whose column chunks do not match their checksum is removed and its cases are
computed again (one line on stderr each). The checksum is checked before any column is decoded."""
from __future__ import annotations

import base64
import hashlib
import json
import os
import re
import shutil
import stat
import struct
import sys
import zlib
from pathlib import Path

import numpy as np

from ..output_files import OutputWriteError, atomic_write, file_kind, os_reason
from .parquet_join import MAGIC
from .table import (COLUMNS, VALIDITY, assemble, chunk_table, csv_header, parquet_options,
                    pair_codes, table_counts, write_csv_rows)

__all__ = ["PartStore", "ResumeError", "PartError", "write_from_parts"]

#: A part file's name: its first case and one past its last, 15 digits each.
PART_NAME = re.compile(r"chunk-(\d{15})-(\d{15})\.parquet")
#: The footer key of a part's record.
RECORD_KEY = b"restitution.part"
#: The footer key of the Arrow schema (pyarrow's: the base64 of the schema's IPC message).
ARROW_SCHEMA = b"ARROW:schema"
#: Columns a part's counts are made from (:func:`restitution.sweep.table.table_counts`).
COUNT_COLUMNS = ("case", "ok", *VALIDITY)


class ResumeError(ValueError):
    """``resume=True`` on the finished chunks of another sweep (spec, back end, chunk size or columns),
    or on a damaged part that cannot be removed."""


class PartError(ValueError):
    """A part file that cannot be used (``reason``: one line saying why)."""

    def __init__(self, file, reason: str):
        super().__init__(f"{file}: {reason}")
        self.file, self.reason = Path(file), reason


class PartStore:
    """Finished chunks of one sweep on disk: ``chunk-<start>-<stop>.parquet`` and ``manifest.json``.
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
        return self.path / f"chunk-{a:015d}-{b:015d}.parquet"

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
        self.spec, self.keep = spec, keep
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
                columns, info = self.read(a, b, load_columns=load_columns or on_chunk is not None)
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

    def read(self, a: int, b: int, load_columns: bool = True):
        """(columns or None, info) of the chunk of cases ``a`` to ``b - 1``, checked: a regular file, a
        readable Parquet file of this sweep's columns, its recorded range ``[a, b]`` and sweep, the
        CRC-32 of its column chunks (before any is decoded), its ``case`` column ``a ... b - 1``.
        PartError (one line) otherwise. ``pair`` reads as the spec's pair index (-1: no pairs)."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        file = self.file(a, b)
        try:
            st = os.lstat(file)
        except OSError as exc:
            raise PartError(file, f"cannot be read ({os_reason(exc)})") from None
        if not stat.S_ISREG(st.st_mode):
            kind = "a symlink" if stat.S_ISLNK(st.st_mode) else file_kind(st.st_mode)
            raise PartError(file, f"is {kind}, not a part this sweep wrote")
        try:
            # read into Arrow's memory, not a Python bytes object: Arrow's reader threads release their
            # last reference to a Python-owned buffer under the GIL, and one doing it while the interpreter
            # exits aborted the process ("terminate called without an active exception", about 1 run in
            # 30 of a script that reads parts and exits at once; none in 150 from Arrow's memory)
            with pa.OSFile(str(file)) as f:
                data = f.read_buffer()
            meta = pq.read_metadata(pa.BufferReader(data))
            raw = (meta.metadata or {}).get(RECORD_KEY)
            info = json.loads(raw) if raw is not None else None
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
        if record.get("sweep") != self.sweep:
            raise PartError(file, "belongs to another sweep")
        if record.get("crc32") != _body_crc(data):
            raise PartError(file, "its column chunks do not match their checksum (CRC-32)")
        names = [c for c in COLUMNS if self.keep is None or c in self.keep]
        if meta.num_rows != b - a or meta.schema.to_arrow_schema().names != names:
            raise PartError(file, f"holds {meta.num_rows:,} rows of other columns than this sweep's")
        if not (isinstance(info.get("code"), str) and isinstance(info.get("pid"), int)
                and isinstance(info.get("cpu"), (int, float))):
            raise PartError(file, "its record of how it was computed is incomplete")
        try:
            table = pq.read_table(pa.BufferReader(data), columns=None if load_columns else list(COUNT_COLUMNS),
                                  read_dictionary=["pair"] if load_columns else None)
            columns = {name: table.column(name) for name in table.column_names}
            if "pair" in columns:
                columns["pair"] = pair_codes(self.spec, columns["pair"])
            columns = {name: np.asarray(col) if name == "pair" else col.to_numpy() for name, col in columns.items()}
        except Exception as exc:  # noqa: BLE001 - a column that does not decode to its type
            raise PartError(file, f"not a whole part ({type(exc).__name__}: {os_reason(exc)})") from None
        case = columns.get("case")
        if case is None or case.dtype.kind not in "iu" or not np.array_equal(case, np.arange(a, b)):
            raise PartError(file, f"its case column is not {a:,} ... {b - 1:,}")
        info["counts"] = table_counts(columns)  # from the columns themselves, never as recorded
        return (columns if load_columns else None), info

    def write(self, a: int, b: int, part) -> None:
        """The chunk ``a`` ... ``b - 1`` as a part file (Parquet: one row group, the record in its
        footer); written under a temporary name and renamed (an I/O error: OutputWriteError naming
        the part). Not fsynced: --resume verifies every part's checksum and computes a bad one again,
        so a part that a power loss cut short is never used, and a run does not wait for the disk."""
        columns, info = part
        record = {"range": [int(a), int(b)], "sweep": self.sweep, "crc32": _CRC_PENDING}
        text = json.dumps({**info, "part": record}, default=str)
        body, footer = encode_part(chunk_table(self.spec, columns, self.keep), {RECORD_KEY: text.encode()})
        # the record's checksum, once the column chunks it covers are encoded: same length, in place
        pending = json.dumps({"crc32": _CRC_PENDING})[1:-1].encode()
        if footer.count(pending) != 1:
            raise RuntimeError("the part's record is not in its footer once")
        footer = footer.replace(pending, json.dumps({"crc32": f"{zlib.crc32(body):08x}"})[1:-1].encode())

        def write_to(tmp):
            with open(tmp, "wb") as f:
                f.write(MAGIC)
                f.write(body)
                f.write(footer)
                f.write(struct.pack("<I", len(footer)) + MAGIC)

        atomic_write(self.file(a, b), write_to, "chunk file", durable=False)

    def remove(self) -> None:
        shutil.rmtree(self.path, ignore_errors=True)


#: A part's checksum until its column chunks are encoded (as long as the CRC-32 in hex).
_CRC_PENDING = "-" * 8


def encode_part(table, key_values: dict) -> tuple[bytes, bytes]:
    """(column chunks, footer) of ``table`` written as one Parquet row group (:func:`parquet_options`),
    with ``key_values`` in the footer's key-value metadata (they are in the footer's Arrow schema too:
    :func:`write_from_parts` writes the table's without them)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    sink = pa.BufferOutputStream()
    table = table.replace_schema_metadata(key_values)
    pq.write_table(table, sink, row_group_size=max(1, table.num_rows), **parquet_options(table.column_names))
    data = memoryview(sink.getvalue())
    length = struct.unpack("<I", data[-8:-4])[0]
    return data[4:-8 - length], bytes(data[-8 - length:-8])


def _body_crc(data) -> str:
    """CRC-32 (hex) of a Parquet file's column chunks: its bytes between the leading magic and the footer."""
    length = struct.unpack("<I", data[-8:-4])[0]
    return f"{zlib.crc32(memoryview(data)[4:len(data) - 8 - length]):08x}"


def part_files(result) -> list[Path]:
    """The part files of ``result``'s finished chunks, in case order."""
    store = PartStore(result.parts)
    return [store.file(a, a + counts["cases"]) for a, counts in sorted(result.chunk_counts.items())]


def write_from_parts(result, path: Path, suffix: str) -> None:
    """The table of ``result`` (its finished chunks in ``result.parts``) written to ``path``: Parquet
    by joining the parts' column chunks (:func:`~restitution.sweep.parquet_join.join_parquet`, nothing
    decoded), CSV by formatting each part's columns in turn. A part that is missing or not one of
    this sweep's: PartError."""
    from .parquet_join import JoinError, join_parquet

    files = part_files(result)
    if suffix.lower() == ".parquet":
        if not files:  # no chunk finished: an empty table with the columns
            import pyarrow.parquet as pq

            table = chunk_table(result.spec, None, result.info.get("keep"))
            pq.write_table(table, path, **parquet_options(table.column_names))
            return
        for file in files:  # each is whole, of this sweep: its record says so (parts are checked when resumed)
            _check_record(file, result.info.get("sweep"))
        schema = chunk_table(result.spec, None, result.info.get("keep")).schema  # the table's, no part's record
        try:
            join_parquet(files, path, drop_keys=(RECORD_KEY,),
                         set_keys={ARROW_SCHEMA: base64.b64encode(schema.serialize().to_pybytes())})
        except JoinError as exc:
            raise PartError(path, f"cannot join the parts ({exc})") from None
        return
    keep = result.info.get("keep")
    store = PartStore(result.parts)
    store.spec, store.keep, store.sweep = result.spec, keep, result.info.get("sweep")
    names = [c for c in COLUMNS if keep is None or c in keep]
    with open(path, "w", encoding="utf-8", newline="") as f:
        f.write(csv_header(names))
        for a, counts in sorted(result.chunk_counts.items()):
            write_csv_rows(f, assemble(result.spec, [store.read(a, a + counts["cases"])[0]], keep))


def _record(file: Path) -> dict:
    """The record in a part's footer (PartError if it has none)."""
    from .parquet_join import JoinError, key_value, read_footer

    try:
        with open(file, "rb") as f:
            footer, _start, _end = read_footer(f)
        raw = key_value(footer, RECORD_KEY)
        record = json.loads(raw) if raw is not None else None
    except (OSError, ValueError, JoinError) as exc:
        raise PartError(file, f"not a whole part ({os_reason(exc)})") from None
    if not isinstance(record, dict) or not isinstance(record.get("part"), dict):
        raise PartError(file, "no record of its case range and checksum")
    return record["part"]


def _check_record(file: Path, sweep) -> None:
    match = PART_NAME.fullmatch(file.name)
    record = _record(file)
    if record.get("range") != [int(match[1]), int(match[2])]:
        raise PartError(file, "holds other cases than its name says (parts swapped or renamed)")
    if record.get("sweep") != sweep:
        raise PartError(file, "belongs to another sweep")
