"""Parquet files of one schema joined into one file by copying their bytes: no column is decoded or
encoded again.

A Parquet file is ``PAR1``, the column chunks of its row groups, the footer (a Thrift-encoded
``FileMetaData``, Thrift compact protocol), the footer's length (4 bytes, little-endian) and ``PAR1``.
The footer locates every column chunk by its absolute offset in the file. Joining files is therefore
copying each one's column chunks after the previous ones and writing one footer listing all their
row groups, each offset moved by where its bytes landed (parquet-format's ``parquet.thrift``: the
fields named in :data:`_OFFSETS`). The footer is read and written by the small Thrift compact codec
below, which keeps every field it does not know as it was read."""
from __future__ import annotations

import errno
import os
import struct

__all__ = ["read_footer", "join_parquet", "key_value", "JoinError"]

MAGIC = b"PAR1"

# Thrift compact protocol type codes
_TRUE, _FALSE, _BYTE, _I16, _I32, _I64, _DOUBLE, _BINARY, _LIST, _SET, _MAP, _STRUCT = range(1, 13)

#: parquet.thrift field ids: FileMetaData.num_rows / row_groups / key_value_metadata, RowGroup.columns /
#: file_offset / ordinal, ColumnChunk.meta_data, KeyValue.key
_NUM_ROWS, _ROW_GROUPS, _KEY_VALUE = 3, 4, 5
_RG_COLUMNS, _RG_FILE_OFFSET, _RG_ORDINAL = 1, 5, 7
_CC_META = 3
_KV_KEY = 1
#: the absolute file offsets: in ColumnChunk (file_offset, offset_index_offset, column_index_offset)
#: and in ColumnMetaData (data_page_offset, index_page_offset, dictionary_page_offset, bloom_filter_offset)
_OFFSETS = {"chunk": (2, 4, 6), "meta": (9, 10, 11, 14)}


class JoinError(ValueError):
    """A file that is not a Parquet file this module can join (one line)."""


class _Reader:
    def __init__(self, data: bytes):
        self.data, self.pos = data, 0

    def byte(self) -> int:
        if self.pos >= len(self.data):
            raise JoinError("the footer ends early")
        self.pos += 1
        return self.data[self.pos - 1]

    def varint(self) -> int:
        shift = result = 0
        while True:
            b = self.byte()
            result |= (b & 0x7F) << shift
            if not b & 0x80:
                return result
            shift += 7
            if shift > 70:
                raise JoinError("a varint longer than 10 bytes")

    def zigzag(self) -> int:
        n = self.varint()
        return (n >> 1) ^ -(n & 1)

    def raw(self, n: int) -> bytes:
        if n < 0 or self.pos + n > len(self.data):
            raise JoinError("the footer ends early")
        self.pos += n
        return self.data[self.pos - n:self.pos]

    def value(self, kind: int, depth: int):
        if depth > 32:
            raise JoinError("the footer nests too deep")
        if kind in (_TRUE, _FALSE):  # an element of a list: one byte
            return self.byte() == 1
        if kind == _BYTE:
            return self.byte()
        if kind in (_I16, _I32, _I64):
            return self.zigzag()
        if kind == _DOUBLE:
            return struct.unpack("<d", self.raw(8))[0]
        if kind == _BINARY:
            return self.raw(self.varint())
        if kind in (_LIST, _SET):
            head = self.byte()
            size, elem = head >> 4, head & 0x0F
            if size == 15:
                size = self.varint()
            return elem, [self.value(elem, depth + 1) for _ in range(size)]
        if kind == _MAP:
            size = self.varint()
            kinds = self.byte() if size else 0
            return kinds, [(self.value(kinds >> 4, depth + 1), self.value(kinds & 0x0F, depth + 1)) for _ in range(size)]
        if kind == _STRUCT:
            return self.struct(depth + 1)
        raise JoinError(f"unknown Thrift type {kind}")

    def struct(self, depth: int = 0) -> list:
        """[(field id, type, value)], in the order read; a bool's value is in its type."""
        fields, last = [], 0
        while True:
            head = self.byte()
            if head == 0:
                return fields
            kind, delta = head & 0x0F, head >> 4
            fid = last + delta if delta else self.zigzag()
            value = (kind == _TRUE) if kind in (_TRUE, _FALSE) else self.value(kind, depth)
            fields.append([fid, kind, value])
            last = fid


def _varint(n: int) -> bytes:
    out = bytearray()
    while True:
        if n < 0x80:
            out.append(n)
            return bytes(out)
        out.append((n & 0x7F) | 0x80)
        n >>= 7


def _zigzag(n: int) -> bytes:
    return _varint((n << 1) ^ (n >> 63))


def _write_value(out: bytearray, kind: int, value) -> None:
    if kind in (_TRUE, _FALSE):
        out.append(1 if value else 2)
    elif kind == _BYTE:
        out.append(value)
    elif kind in (_I16, _I32, _I64):
        out += _zigzag(value)
    elif kind == _DOUBLE:
        out += struct.pack("<d", value)
    elif kind == _BINARY:
        out += _varint(len(value)) + value
    elif kind in (_LIST, _SET):
        elem, items = value
        out.append((len(items) << 4 | elem) if len(items) < 15 else (0xF0 | elem))
        if len(items) >= 15:
            out += _varint(len(items))
        for item in items:
            _write_value(out, elem, item)
    elif kind == _MAP:
        kinds, items = value
        out += _varint(len(items))
        if items:
            out.append(kinds)
        for k, v in items:
            _write_value(out, kinds >> 4, k)
            _write_value(out, kinds & 0x0F, v)
    elif kind == _STRUCT:
        _write_struct(out, value)


def _write_struct(out: bytearray, fields: list) -> None:
    last = 0
    for fid, kind, value in fields:
        wire = (_TRUE if value else _FALSE) if kind in (_TRUE, _FALSE) else kind
        if 0 < fid - last <= 15:
            out.append((fid - last) << 4 | wire)
        else:
            out.append(wire)
            out += _zigzag(fid)
        if kind not in (_TRUE, _FALSE):
            _write_value(out, kind, value)
        last = fid
    out.append(0)


def _field(fields: list, fid: int):
    return next((f for f in fields if f[0] == fid), None)


def read_footer(f) -> tuple[list, int, int]:
    """(the decoded FileMetaData, where the column chunks start, where they end) of the open binary
    file ``f``: the bytes between those two are what a join copies."""
    size = f.seek(0, os.SEEK_END)
    if size < 12:
        raise JoinError("too short for a Parquet file")
    f.seek(size - 8)
    tail = f.read(8)
    length = struct.unpack("<I", tail[:4])[0]
    if tail[4:] != MAGIC or length > size - 12:
        raise JoinError("no Parquet footer at its end")
    f.seek(size - 8 - length)
    footer = _Reader(f.read(length)).struct()
    f.seek(0)
    if f.read(4) != MAGIC:
        raise JoinError("no Parquet magic at its start")
    return footer, 4, size - 8 - length


def key_value(footer: list, key: bytes) -> bytes | None:
    """The value of ``key`` in the footer's key-value metadata, or None."""
    kv = _field(footer, _KEY_VALUE)
    for entry in (kv[2][1] if kv else []):
        k, v = _field(entry, _KV_KEY), _field(entry, 2)
        if k is not None and k[2] == key:
            return v[2] if v is not None else b""
    return None


def _shift(fields: list, ids, by: int) -> None:
    for f in fields:
        if f[0] in ids and f[1] == _I64:
            f[2] += by


def join_parquet(files, out, drop_keys=(), set_keys=None) -> int:
    """Write the Parquet files ``files`` (one schema; row groups in the order given) as one file
    ``out``, copying their column chunks; the footer is the first file's with every row group and
    the rows summed, less the key-value entries ``drop_keys``, with the values of ``set_keys`` (key ->
    value, bytes) in place of its own. The rows written."""
    set_keys = dict(set_keys or {})
    head, groups, rows = None, [], 0
    with open(out, "wb", buffering=0) as dst:
        pos = _write_all(dst.fileno(), MAGIC, 0)
        for file in files:
            with open(file, "rb", buffering=0) as src:
                footer, start, end = read_footer(src)
                shift = pos - start
                pos = _copy(src.fileno(), start, dst.fileno(), pos, end - start)
            for group in (_field(footer, _ROW_GROUPS) or [0, 0, (_STRUCT, [])])[2][1]:
                _shift(group, (_RG_FILE_OFFSET,), shift)
                for chunk in _field(group, _RG_COLUMNS)[2][1]:
                    _shift(chunk, _OFFSETS["chunk"], shift)
                    meta = _field(chunk, _CC_META)
                    if meta is not None:
                        _shift(meta[2], _OFFSETS["meta"], shift)
                ordinal = _field(group, _RG_ORDINAL)
                if ordinal is not None:
                    ordinal[2] = len(groups)
                groups.append(group)
            rows += _field(footer, _NUM_ROWS)[2]
            head = head or footer
        if head is None:
            raise JoinError("no file to join")
        footer = []
        for fid, kind, value in head:
            if fid == _NUM_ROWS:
                value = rows
            elif fid == _ROW_GROUPS:
                value = (_STRUCT, groups)
            elif fid == _KEY_VALUE:
                kept = [e for e in value[1] if _field(e, _KV_KEY)[2] not in (*drop_keys, *set_keys)]
                value = (_STRUCT, kept + [[[_KV_KEY, _BINARY, k], [2, _BINARY, v]] for k, v in set_keys.items()])
            footer.append([fid, kind, value])
        encoded = bytearray()
        _write_struct(encoded, footer)
        _write_all(dst.fileno(), bytes(encoded) + struct.pack("<I", len(encoded)) + MAGIC, pos)
    return rows


def _write_all(fd: int, data: bytes, pos: int) -> int:
    view = memoryview(data)
    while view:
        done = os.pwrite(fd, view, pos)
        view, pos = view[done:], pos + done
    return pos


def _copy(src: int, src_pos: int, dst: int, dst_pos: int, n: int) -> int:
    """``n`` bytes of ``src`` from ``src_pos`` into ``dst`` at ``dst_pos``, in the kernel where it can
    (no copy through this process); where ``dst`` is then."""
    end = src_pos + n
    try:
        while src_pos < end:
            done = os.copy_file_range(src, dst, end - src_pos, src_pos, dst_pos)
            if done == 0:
                raise JoinError("the file ended before its footer")
            src_pos, dst_pos = src_pos + done, dst_pos + done
        return dst_pos
    except (AttributeError, OSError) as exc:  # no copy_file_range here (or across these file systems)
        if isinstance(exc, OSError) and exc.errno not in (errno.EXDEV, errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
            raise
    while src_pos < end:
        block = os.pread(src, min(end - src_pos, 1 << 24), src_pos)
        if not block:
            raise JoinError("the file ended before its footer")
        dst_pos = _write_all(dst, block, dst_pos)
        src_pos += len(block)
    return dst_pos
