"""Finished chunks on disk: the part store a sweep writes each chunk to as it completes (and resumes
from), and the result whose table stays there (streamed chunk by chunk when written)."""
from __future__ import annotations

import json
import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .table import (COLUMNS, VALIDITY, SweepResult, arrow_table, assemble, parquet_options, table_counts,
                    write_csv_rows)

__all__ = ["PartStore", "DiskSweepResult", "ResumeError"]

class ResumeError(ValueError):
    """``resume=True`` on the finished chunks of another sweep (spec, back end, chunk size or columns)."""


class PartStore:
    """Finished chunks of one sweep on disk: ``chunk-<start>-<stop>.npz`` and ``manifest.json``."""

    def __init__(self, path: Path):
        self.path = path

    def manifest(self):
        try:
            return json.loads((self.path / "manifest.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None

    def open(self, spec, backend, chunk_size, keep, resume: bool, load_columns: bool = True) -> dict:
        """Chunks already finished (``resume``; start -> (columns, info), columns None unless
        ``load_columns``), after checking that they belong to this sweep; without ``resume``, an
        empty directory."""
        manifest = {"spec": spec.as_dict(), "backend": backend.name, "chunk_size": int(chunk_size),
                    "n_cases": int(spec.n_cases), "columns": None if keep is None else sorted(keep)}
        old = self.manifest() if resume else None
        if old is not None and old != json.loads(json.dumps(manifest)):
            raise ResumeError(f"--resume: the finished chunks in {self.path} belong to another sweep "
                             f"(spec, back end or columns differ); run without --resume to start over")
        if old is None and self.path.exists():
            shutil.rmtree(self.path)
        self.path.mkdir(parents=True, exist_ok=True)
        if old is None:
            self._write_text("manifest.json", json.dumps(manifest, indent=1))
        done = {}
        for file in sorted(self.path.glob("chunk-*.npz")):
            a = int(file.stem.split("-")[1])
            done[a] = self.read(a, file, load_columns)
        return done

    def _file(self, a: int) -> Path:
        return next(self.path.glob(f"chunk-{a:015d}-*.npz"))

    def read(self, a: int, file: Path | None = None, load_columns: bool = True):
        """(columns or None, info) of the chunk starting at case ``a``."""
        with np.load(file or self._file(a), allow_pickle=False) as z:
            info = json.loads(str(z["info"]))
            columns = None
            if load_columns or "counts" not in info:
                columns = {k[2:]: z[k] for k in z.files if k.startswith("c:")}
                info.setdefault("counts", table_counts(columns))
        return (columns if load_columns else None), info

    def write(self, a: int, b: int, part) -> None:
        columns, info = part
        tmp = self.path / f".chunk-{a}-{b}.tmp.npz"
        np.savez(tmp, info=np.array(json.dumps(info, default=str)), **{f"c:{k}": v for k, v in columns.items()})
        os.replace(tmp, self.path / f"chunk-{a:015d}-{b:015d}.npz")

    def _write_text(self, name, text):
        tmp = self.path / f".{name}.tmp"
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, self.path / name)

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
        if suffix.lower() == ".parquet":
            import pyarrow.parquet as pq

            writer = None
            try:
                for a in starts:
                    cols = assemble(self.spec, [store.read(a)[0]], keep)
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
                write_csv_rows(f, assemble(self.spec, [store.read(a)[0]], keep))

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
