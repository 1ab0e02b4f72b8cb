"""Reproducible archives (restitution.reproducible.write_zip, the writer of every FMU): the same contents
give the same bytes whatever order they come in, whenever they are written and under whatever umask; the
entries' times are SOURCE_DATE_EPOCH's or 1980-01-01, their permissions fixed. Two whole builds of every
FMU giving the same bytes: tests/fmu/test_fmu_identity.py (test_two_builds_write_byte_identical_fmus)."""
from __future__ import annotations

import hashlib
import os
import stat
import time
import zipfile

import pytest

from restitution.reproducible import write_zip, zip_date_time, zip_directory

ENTRIES = {"modelDescription.xml": b"<fmiModelDescription/>", "binaries/linux64/M.so": b"\x7fELF" + bytes(60),
           "sources/m.c": b"int x;\n", "documentation/licenses/license.txt": b"MIT\n"}


def _digest(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_same_entries_in_any_order_at_any_time_give_the_same_bytes(tmp_path, monkeypatch):
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    first = write_zip(tmp_path / "a.zip", ENTRIES)
    time.sleep(2.1)  # zip times have a two-second resolution: a time taken from the clock would differ
    old = os.umask(0o077)
    try:
        second = write_zip(tmp_path / "b.zip", list(reversed(ENTRIES.items())))
    finally:
        os.umask(old)
    assert _digest(first) == _digest(second)


def test_entries_are_sorted_dated_and_have_fixed_permissions(tmp_path, monkeypatch):
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    with zipfile.ZipFile(write_zip(tmp_path / "a.zip", ENTRIES)) as z:
        infos = z.infolist()
    assert [i.filename for i in infos] == sorted(ENTRIES)
    for info in infos:
        assert info.date_time == (1980, 1, 1, 0, 0, 0)
        assert info.create_system == 3 and stat.S_ISREG(info.external_attr >> 16)
        assert stat.S_IMODE(info.external_attr >> 16) == (0o755 if info.filename.startswith("binaries/") else 0o644)
        assert info.compress_type == zipfile.ZIP_DEFLATED


@pytest.mark.parametrize("epoch, expected", [
    ("1764064800", (2025, 11, 25, 10, 0, 0)),   # 2025-11-25T10:00:00Z (date -u -d @1764064800)
    ("0", (1980, 1, 1, 0, 0, 0)),               # 1970: before the first time a zip entry can state
    ("99999999999", (2107, 12, 31, 23, 59, 58)),  # year 5138: after the last
])
def test_entry_times_come_from_source_date_epoch(tmp_path, epoch, expected):
    assert zip_date_time({"SOURCE_DATE_EPOCH": epoch}) == expected
    with zipfile.ZipFile(write_zip(tmp_path / "a.zip", ENTRIES, environ={"SOURCE_DATE_EPOCH": epoch})) as z:
        assert {i.date_time for i in z.infolist()} == {expected}


def test_a_malformed_source_date_epoch_is_refused(tmp_path):
    with pytest.raises(ValueError, match="SOURCE_DATE_EPOCH"):
        write_zip(tmp_path / "a.zip", ENTRIES, environ={"SOURCE_DATE_EPOCH": "yesterday"})


def test_a_name_given_twice_is_refused(tmp_path):
    with pytest.raises(ValueError, match="twice"):
        write_zip(tmp_path / "a.zip", [("a", b"1"), ("a", b"2")])


def test_a_directory_written_twice_at_different_times_gives_the_same_bytes(tmp_path, monkeypatch):
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    for name, data in ENTRIES.items():
        (tmp_path / "stage" / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "stage" / name).write_bytes(data)
    first = zip_directory(tmp_path / "stage", tmp_path / "a.zip")
    os.utime(tmp_path / "stage" / "sources" / "m.c", (1e9, 1e9))  # a file time changes, its content does not
    (tmp_path / "stage" / "sources" / "m.c").chmod(0o600)
    second = zip_directory(tmp_path / "stage", tmp_path / "b.zip")
    assert _digest(first) == _digest(second)
    assert _digest(first) == _digest(write_zip(tmp_path / "c.zip", ENTRIES))
