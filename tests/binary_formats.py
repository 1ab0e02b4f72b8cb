"""What a shared library is, read from its bytes: its format (ELF, PE or Mach-O), the architecture it is
for, the names it exports, the libraries it needs and a few details a loader cares about. Pure Python
(struct), for the tests of the native FMUs' binaries on every platform (tests/fmu/test_cross_binaries.py),
which this machine can neither load nor, for most, run.

* ELF (Linux): the 64-bit little-endian file header (e_machine), the dynamic symbol table (``.dynsym``:
  the symbols defined there with global or weak binding and default or protected visibility are the
  exports), the dynamic section (DT_NEEDED, DT_SONAME) and the version needs (``.gnu.version_r``: the
  ``GLIBC_x.y`` symbol versions a loader must find, :func:`glibc_version` the highest).
* PE (Windows): the COFF header (Machine, Characteristics), the PE32+ optional header's data
  directories: the export directory (its DLL name and the names it exports) and the import directory
  (the DLLs it needs).
* Mach-O (macOS): a thin 64-bit image or a universal ("fat") file of several; per image the CPU type,
  the export trie (LC_DYLD_INFO[_ONLY] or LC_DYLD_EXPORTS_TRIE), the external symbols of the symbol table
  (LC_SYMTAB), the dylibs it loads (LC_LOAD_DYLIB), its install name (LC_ID_DYLIB), its minimum macOS
  (LC_BUILD_VERSION or LC_VERSION_MIN_MACOSX) and whether it carries a code signature
  (LC_CODE_SIGNATURE). C names carry a leading underscore in Mach-O; the names given here do not.

:func:`read_images` returns one :class:`Image` per architecture in the file (a universal Mach-O has
several); anything it cannot read raises :class:`FormatError` saying what.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass, field


class FormatError(ValueError):
    """The bytes are not a shared library of a format read here, or are damaged."""


@dataclass(frozen=True)
class Image:
    """One architecture's shared library."""

    format: str  #: "ELF", "PE" or "Mach-O"
    arch: str  #: "x86_64" or "aarch64" (else the format's own number, e.g. "e_machine 40")
    exports: frozenset  #: the names of the exported symbols (Mach-O: without the leading underscore)
    needed: tuple = ()  #: the libraries it loads (ELF DT_NEEDED, PE imported DLLs, Mach-O LC_LOAD_DYLIB)
    shared: bool = True  #: a shared library (ELF ET_DYN, a PE DLL, Mach-O MH_DYLIB)
    details: dict = field(default_factory=dict, compare=False)  #: what else the format tells (see the readers)


def _cstring(data: bytes, offset: int) -> str:
    end = data.find(b"\0", offset)
    if offset < 0 or offset >= len(data) or end < 0:
        raise FormatError(f"string at {offset} outside the file")
    return data[offset:end].decode("utf-8", "replace")


def _unpack(fmt: str, data: bytes, offset: int) -> tuple:
    if offset < 0 or offset + struct.calcsize(fmt) > len(data):
        raise FormatError(f"{struct.calcsize(fmt)} bytes at {offset} outside the file ({len(data)} bytes)")
    return struct.unpack_from(fmt, data, offset)


def read_images(data: bytes) -> list[Image]:
    """Every image of a shared library's bytes (one, or each slice of a universal Mach-O)."""
    if data[:4] == b"\x7fELF":
        return [read_elf(data)]
    if data[:2] == b"MZ":
        return [read_pe(data)]
    if data[:4] == b"\xca\xfe\xba\xbe":
        return read_fat(data)
    if data[:4] == b"\xcf\xfa\xed\xfe":
        return [read_macho(data)]
    raise FormatError(f"not an ELF, PE or Mach-O file (starts with {data[:4].hex()})")


# --- ELF -------------------------------------------------------------------------------------------
ELF_MACHINES = {62: "x86_64", 183: "aarch64"}
SHT_DYNSYM, SHT_DYNAMIC, SHT_GNU_VERNEED = 11, 6, 0x6FFFFFFE
DT_NEEDED, DT_SONAME = 1, 14
STB_GLOBAL, STB_WEAK = 1, 2
STV_DEFAULT, STV_PROTECTED = 0, 3


def _version_needs(data: bytes, offset: int, strtab: int) -> dict[str, tuple[str, ...]]:
    """The version-needs section (``.gnu.version_r``): library -> the symbol versions the file needs of it
    (e.g. ``{"libc.so.6": ("GLIBC_2.2.5", "GLIBC_2.3.4")}``). A chain of Elf64_Verneed records (vn_version,
    vn_cnt, vn_file, vn_aux, vn_next), each followed via vn_aux by vn_cnt Elf64_Vernaux records (vna_hash,
    vna_flags, vna_other, vna_name, vna_next); offsets are relative to the record holding them."""
    needs: dict[str, tuple[str, ...]] = {}
    for _ in range(1 << 12):  # a bound, so that a damaged chain cannot loop forever
        version, count, file, aux, following = _unpack("<HHIII", data, offset)
        if version != 1:
            raise FormatError(f"Elf64_Verneed version {version} (1 expected)")
        names, at = [], offset + aux
        for _k in range(count):
            _hash, _flags, _other, name, next_aux = _unpack("<IHHII", data, at)
            names.append(_cstring(data, strtab + name))
            at += next_aux
        needs[_cstring(data, strtab + file)] = tuple(names)
        if not following:
            return needs
        offset += following
    raise FormatError("the version-needs chain does not end")


def glibc_version(needs: dict[str, tuple[str, ...]]) -> tuple[int, ...] | None:
    """The highest ``GLIBC_x.y[.z]`` version of ``needs`` (:func:`_version_needs`), as numbers; None where it
    needs none."""
    found = [tuple(int(part) for part in name[len("GLIBC_"):].split("."))
             for names in needs.values() for name in names
             if name.startswith("GLIBC_") and name[len("GLIBC_"):].replace(".", "").isdigit()]
    return max(found, default=None)


def read_elf(data: bytes) -> Image:
    """A 64-bit little-endian ELF file: its machine, exports (.dynsym), DT_NEEDED, DT_SONAME and the symbol
    versions it needs (``details["version_needs"]``, from .gnu.version_r)."""
    if data[4] != 2 or data[5] != 1:
        raise FormatError(f"ELF class {data[4]}, data encoding {data[5]}: only 64-bit little-endian is read")
    e_type, e_machine = _unpack("<HH", data, 16)
    e_shoff, = _unpack("<Q", data, 0x28)
    e_shentsize, e_shnum = _unpack("<HH", data, 0x3A)
    sections = [_unpack("<IIQQQQIIQQ", data, e_shoff + i * e_shentsize) for i in range(e_shnum)]
    exports, needed, details = set(), [], {}
    for sh_name, sh_type, _flags, _addr, sh_offset, sh_size, sh_link, _info, _align, sh_entsize in sections:
        if sh_type == SHT_DYNSYM:
            strtab = sections[sh_link][4]
            for k in range(1, sh_size // sh_entsize):  # entry 0 is the null symbol
                st_name, st_info, st_other, st_shndx = _unpack("<IBBH", data, sh_offset + k * sh_entsize)
                if (st_shndx != 0 and st_info >> 4 in (STB_GLOBAL, STB_WEAK)
                        and st_other & 3 in (STV_DEFAULT, STV_PROTECTED)):
                    exports.add(_cstring(data, strtab + st_name))
        elif sh_type == SHT_GNU_VERNEED:
            details["version_needs"] = _version_needs(data, sh_offset, sections[sh_link][4])
        elif sh_type == SHT_DYNAMIC:
            strtab = sections[sh_link][4]
            for k in range(sh_size // 16):
                tag, value = _unpack("<qQ", data, sh_offset + 16 * k)
                if tag == DT_NEEDED:
                    needed.append(_cstring(data, strtab + value))
                elif tag == DT_SONAME:
                    details["soname"] = _cstring(data, strtab + value)
    return Image("ELF", ELF_MACHINES.get(e_machine, f"e_machine {e_machine}"), frozenset(exports), tuple(needed),
                 e_type == 3, details)


# --- PE ----------------------------------------------------------------------------------------------
PE_MACHINES = {0x8664: "x86_64", 0xAA64: "aarch64"}
IMAGE_FILE_DLL = 0x2000


def read_pe(data: bytes) -> Image:
    """A PE32+ image: its machine, the DLL name and names of its export directory, the DLLs it imports and
    the COFF header's TimeDateStamp."""
    pe, = _unpack("<I", data, 0x3C)
    if data[pe:pe + 4] != b"PE\0\0":
        raise FormatError("no PE signature where the DOS header points")
    machine, n_sections, timestamp, _symtab, _nsyms, opt_size, characteristics = _unpack("<HHIIIHH", data, pe + 4)
    opt = pe + 24
    magic, = _unpack("<H", data, opt)
    if magic != 0x20B:
        raise FormatError(f"optional header magic {magic:#x}: only PE32+ (0x20b) is read")
    n_dirs, = _unpack("<I", data, opt + 108)
    directories = [_unpack("<II", data, opt + 112 + 8 * i) for i in range(min(n_dirs, 16))]
    sections = [_unpack("<8sIIII", data, opt + opt_size + 40 * i) for i in range(n_sections)]

    def offset(rva: int) -> int:
        for _name, vsize, vaddr, raw_size, raw_ptr in sections:
            if vaddr <= rva < vaddr + max(vsize, raw_size):
                return raw_ptr + rva - vaddr
        raise FormatError(f"RVA {rva:#x} in no section")

    exports, needed, details = set(), [], {"timestamp": timestamp}
    if directories and directories[0][0]:
        export_dir = offset(directories[0][0])
        name_rva, _base, _n_functions, n_names, _functions, names = _unpack("<IIIIII", data, export_dir + 12)
        details["dll_name"] = _cstring(data, offset(name_rva))
        for k in range(n_names):
            exports.add(_cstring(data, offset(_unpack("<I", data, offset(names) + 4 * k)[0])))
    if len(directories) > 1 and directories[1][0]:
        descriptor = offset(directories[1][0])
        while True:
            lookup, _time, _chain, name_rva, thunks = _unpack("<IIIII", data, descriptor)
            if not (lookup or name_rva or thunks):
                break
            needed.append(_cstring(data, offset(name_rva)))
            descriptor += 20
    return Image("PE", PE_MACHINES.get(machine, f"machine {machine:#x}"), frozenset(exports), tuple(needed),
                 bool(characteristics & IMAGE_FILE_DLL), details)


# --- Mach-O ------------------------------------------------------------------------------------------
MACHO_CPUS = {0x01000007: "x86_64", 0x0100000C: "aarch64"}
MH_DYLIB = 6
LC_SYMTAB, LC_LOAD_DYLIB, LC_ID_DYLIB, LC_CODE_SIGNATURE = 0x2, 0xC, 0xD, 0x1D
LC_VERSION_MIN_MACOSX, LC_BUILD_VERSION = 0x24, 0x32
LC_DYLD_INFO, LC_DYLD_INFO_ONLY, LC_DYLD_EXPORTS_TRIE = 0x22, 0x80000022, 0x80000033
LC_REQ_DYLD = 0x80000000
N_STAB, N_PEXT, N_TYPE, N_EXT, N_SECT = 0xE0, 0x10, 0x0E, 0x01, 0x0E


def read_fat(data: bytes) -> list[Image]:
    """Each slice of a universal Mach-O file (big-endian fat header of 32-bit entries)."""
    count, = _unpack(">I", data, 4)
    images = []
    for k in range(count):
        cputype, _subtype, offset, size, _align = _unpack(">iiIII", data, 8 + 20 * k)
        image = read_macho(data[offset:offset + size])
        if MACHO_CPUS.get(cputype & 0xFFFFFFFF, None) != image.arch:
            raise FormatError(f"fat entry {k} says CPU {cputype:#x}, its slice is {image.arch}")
        image.details.update(fat_offset=offset, fat_align=_align)
        images.append(image)
    return images


def _uleb(data: bytes, pos: int) -> tuple[int, int]:
    value = shift = 0
    while True:
        if pos >= len(data):
            raise FormatError("ULEB128 runs past the export trie")
        byte = data[pos]
        pos += 1
        value |= (byte & 0x7F) << shift
        shift += 7
        if byte < 0x80:
            return value, pos


def export_trie(trie: bytes) -> set[str]:
    """The symbol names of a Mach-O export trie (each terminal node is one exported name)."""
    names, todo, seen = set(), [(0, "")], set()
    while todo:
        node, prefix = todo.pop()
        if node in seen:
            raise FormatError("the export trie has a cycle")
        seen.add(node)
        terminal_size, pos = _uleb(trie, node)
        if terminal_size:
            names.add(prefix)
        pos += terminal_size
        children = trie[pos]
        pos += 1
        for _ in range(children):
            end = trie.index(b"\0", pos)
            label = trie[pos:end].decode("utf-8", "replace")
            child, pos = _uleb(trie, end + 1)
            todo.append((child, prefix + label))
    return names


def _version(packed: int) -> str:
    return f"{packed >> 16}.{(packed >> 8) & 0xFF}.{packed & 0xFF}"


def read_macho(data: bytes) -> Image:
    """A thin 64-bit little-endian Mach-O image: CPU, exports (the export trie; the symbol table's external
    defined symbols in ``details["symtab_exports"]``), dylibs loaded, install name, minimum macOS, code
    signature."""
    magic, cputype, _subtype, filetype, ncmds, _size, _flags = _unpack("<IiiIIII", data, 0)
    if magic != 0xFEEDFACF:
        raise FormatError(f"Mach-O magic {magic:#x}: only 64-bit little-endian images are read")
    pos, needed = 32, []
    details = {"signed": False}
    trie = None
    for _ in range(ncmds):
        cmd, cmdsize = _unpack("<II", data, pos)
        if cmd == LC_SYMTAB:
            symoff, nsyms, stroff, _strsize = _unpack("<IIII", data, pos + 8)
            symbols = set()
            for k in range(nsyms):
                n_strx, n_type, _sect, _desc, _value = _unpack("<IBBHQ", data, symoff + 16 * k)
                if not n_type & N_STAB and n_type & N_EXT and not n_type & N_PEXT and n_type & N_TYPE == N_SECT:
                    symbols.add(_cstring(data, stroff + n_strx))
            details["symtab_exports"] = frozenset(s[1:] if s.startswith("_") else s for s in symbols)
        elif cmd in (LC_DYLD_INFO, LC_DYLD_INFO_ONLY):
            export_off, export_size = _unpack("<II", data, pos + 40)
            trie = data[export_off:export_off + export_size] if export_size else b""
        elif cmd == LC_DYLD_EXPORTS_TRIE:
            dataoff, datasize = _unpack("<II", data, pos + 8)
            trie = data[dataoff:dataoff + datasize]
        elif cmd in (LC_LOAD_DYLIB, LC_ID_DYLIB) or cmd == LC_LOAD_DYLIB | LC_REQ_DYLD:
            name = _cstring(data[:pos + cmdsize], pos + _unpack("<I", data, pos + 8)[0])
            if cmd == LC_ID_DYLIB:
                details["install_name"] = name
            else:
                needed.append(name)
        elif cmd == LC_BUILD_VERSION:
            platform, minos, _sdk = _unpack("<III", data, pos + 8)
            details.update(platform=platform, min_os=_version(minos))
        elif cmd == LC_VERSION_MIN_MACOSX:
            details.update(platform=1, min_os=_version(_unpack("<I", data, pos + 8)[0]))
        elif cmd == LC_CODE_SIGNATURE:
            details["signed"] = True
        pos += cmdsize
    if trie is not None:
        exports = frozenset(s[1:] if s.startswith("_") else s for s in export_trie(trie)) if trie else frozenset()
    else:
        exports = details.get("symtab_exports", frozenset())
    return Image("Mach-O", MACHO_CPUS.get(cputype & 0xFFFFFFFF, f"cputype {cputype:#x}"), exports, tuple(needed),
                 filetype == MH_DYLIB, details)
