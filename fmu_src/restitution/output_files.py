"""The files the command-line tools write (sweep tables and COR maps, scene CSVs, plots and reports):
checked before any work, and written whole or not at all. One copy of this logic, for
``restitution.sweep`` and ``restitution.scene``.

- :func:`check_output` refuses, before any work, an output path that exists and is not a regular
  file (a directory, a character or block device, a FIFO, a socket, or a symlink to one): renaming a
  file over ``/dev/full`` replaced the device node. Its directory is created if missing and must
  accept a new file (checked by writing one: permission bits lie to root).
- :func:`atomic_write` writes a file under a temporary name in the same directory, fsyncs it, checks
  the destination again and renames the file over it: the old file stays whole until the new one is.
  A failure removes the temporary file.
- :class:`GrowingOutput` is a text file written record by record (a scene's drops): each record is
  fsynced and visible under the final name as soon as it is whole; an I/O error puts back the file
  that was there before (or removes the new one).
- :func:`write_json` writes a JSON record that way (non-finite numbers as null, numpy scalars as numbers).
- :func:`check_outputs` refuses, before any work, an output that names an input of the same command
  or another of its outputs (by resolved path and by device and inode: symlinks and hard links count),
  so that no run overwrites its own data.
- :func:`finish_stdout` flushes what a command printed: standard output on a full disk or a closed
  pipe is one line on stderr and :data:`EXIT_IO_ERROR` (or the reader's exit, 141), never a traceback.
- An I/O error (ENOSPC, EIO, EACCES, ...) is an :class:`OutputWriteError`, whose text is one line
  naming the path and the system's reason; the tools print it and exit with :data:`EXIT_IO_ERROR`.
"""
from __future__ import annotations

import contextlib
import errno
import itertools
import json
import math
import os
import stat
import sys
import tempfile
from pathlib import Path

__all__ = ["EXIT_REFUSED", "EXIT_IO_ERROR", "EXIT_BROKEN_PIPE", "OutputPathError", "OutputWriteError", "os_reason",
           "describe_os_error", "file_kind", "silence_stdout", "check_output", "check_outputs", "check_output_dir",
           "finish_stdout", "atomic_write", "json_ready", "write_json", "GrowingOutput"]

#: Exit status of an output path refused before any work (a user mistake, as the other ones).
EXIT_REFUSED = 2
#: Exit status of an I/O error while writing (sysexits.h EX_IOERR).
EXIT_IO_ERROR = 74
#: Exit status when the reader of standard output went away (a shell's 128 + SIGPIPE).
EXIT_BROKEN_PIPE = 141


class OutputPathError(ValueError):
    """An output path that cannot be written to (one line; refused before any work)."""


class OutputWriteError(OSError):
    """An I/O error writing an output: ``str()`` is one line, ``cannot write PATH: REASON``."""

    def __init__(self, path, exc: OSError):
        super().__init__(exc.errno, exc.strerror or str(exc), str(path))
        self.path, self.reason = Path(path), os_reason(exc)

    def __str__(self):
        return f"cannot write {self.path}: {self.reason}"


def os_reason(exc: BaseException) -> str:
    """The system's reason for ``exc`` on one line, e.g. ``No space left on device (ENOSPC)``."""
    if isinstance(exc, OSError) and exc.strerror:
        code = errno.errorcode.get(exc.errno) if exc.errno else None
        return f"{exc.strerror} ({code})" if code else exc.strerror
    return " ".join(str(exc).split()) or type(exc).__name__


def describe_os_error(exc: OSError) -> str:
    """One line for any OSError: the file it names (if any) and the reason."""
    if isinstance(exc, OutputWriteError):
        return str(exc)
    names = [str(n) for n in (exc.filename, exc.filename2) if n is not None]
    return f"{' -> '.join(names)}: {os_reason(exc)}" if names else os_reason(exc)


_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"))


def file_kind(mode: int) -> str:
    """What a non-regular file is, from its ``st_mode``: "a directory", "a character device", ..."""
    return next((name for test, name in _KINDS if test(mode)), "a special file")


def _target(path: Path) -> Path:
    """The file a write to ``path`` replaces: a symlink's target (resolved), else ``path`` itself."""
    return Path(os.path.realpath(path)) if path.is_symlink() else path


def _refuse_special(path: Path, what: str, wanted: str = "a regular file") -> os.stat_result | None:
    """The stat of ``path`` (following symlinks), None if it does not exist; OutputPathError if it
    exists and is not a regular file (or cannot be looked at)."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return None
    except NotADirectoryError:
        parent = next((p for p in Path(path).parents if p.exists() and not p.is_dir()), Path(path).parent)
        raise OutputPathError(f"{what} {path}: {parent} is not a directory") from None
    except OSError as exc:
        raise OutputPathError(f"{what} {path}: cannot be checked: {os_reason(exc)}") from None
    if not stat.S_ISREG(st.st_mode):
        link = f" (a symlink to {os.path.realpath(path)})" if Path(path).is_symlink() else ""
        raise OutputPathError(f"{what} {path}: is {file_kind(st.st_mode)}{link}, not {wanted}; "
                              f"give the name of a file to write")
    return st


def _probe_dir(directory: Path, what: str, path: Path) -> None:
    """Create ``directory`` if missing and write a file in it (a real write: permission bits lie to root)."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=directory):
            pass
    except OSError as exc:
        raise OutputPathError(f"{what} {path}: cannot write in {directory}: {os_reason(exc)}") from None


def check_output(path, what: str = "--out") -> Path:
    """``path`` if a file can be written there; else OutputPathError (one line naming ``what`` and
    ``path``): it exists and is not a regular file (directory, device, FIFO, socket, or a symlink to
    one), its directory is a file or cannot be written, or the file is read-only. The directory is
    created if missing."""
    path = Path(path)
    st = _refuse_special(path, what)
    dest = _target(path)
    parent = dest.parent
    if parent.exists() and not parent.is_dir():
        raise OutputPathError(f"{what} {path}: {parent} is not a directory")
    _probe_dir(parent, what, path)
    if st is not None and not os.access(dest, os.W_OK):
        raise OutputPathError(f"{what} {path}: not writable")
    return path


def _identity(path) -> tuple[str, tuple[int, int] | None]:
    """(the resolved absolute path, (device, inode) of the file it names or None if none can be seen)."""
    resolved = os.path.normcase(os.path.realpath(os.path.abspath(os.fspath(path))))
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return resolved, None
    return resolved, (st.st_dev, st.st_ino)


def check_outputs(outputs: dict, inputs: dict | None = None) -> None:
    """Refuse (OutputPathError, one line naming both) an output of ``outputs`` (option -> path, None
    skipped) that is the same file as an input of ``inputs`` (name -> path, None skipped) or as
    another output: the same path once symlinks and ``..`` are resolved, or the same device and inode
    (a hard link, or another spelling). Call it before any work: writing an output over an input
    would destroy the data the command reads."""
    seen: list[tuple[str, object, tuple[str, tuple[int, int] | None], bool]] = []
    for name, path in (inputs or {}).items():
        if path is not None:
            seen.append((name, path, _identity(path), True))
    for option, path in outputs.items():
        if path is None:
            continue
        here = _identity(path)
        for name, other, there, is_input in seen:
            if here[0] == there[0] or (here[1] is not None and here[1] == there[1]):
                if is_input:
                    raise OutputPathError(f"{option} {path}: is the input {name} ({other}): writing it would "
                                          "destroy the data; give another file name")
                raise OutputPathError(f"{option} {path}: is the same file as {name} {other}: give each output "
                                      "its own file name")
        seen.append((option, path, here, False))


def silence_stdout() -> None:
    """Point file descriptor 1 at the null device: what is left in sys.stdout's buffer goes nowhere
    at exit instead of failing again ("Exception ignored ...")."""
    with contextlib.suppress(OSError, ValueError, AttributeError):
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
        os.close(fd)


def finish_stdout(prog: str, text: str | None = None) -> int:
    """Print ``text`` (if given) and flush standard output: 0 if it all went out; else, with standard
    output pointed at the null device, :data:`EXIT_BROKEN_PIPE` (silently) where the reader went away
    or :data:`EXIT_IO_ERROR` after one line ``PROG: error: cannot write standard output: REASON`` on
    stderr (a full disk, an I/O error)."""
    try:
        if text is not None:
            print(text)
        sys.stdout.flush()
    except BrokenPipeError:
        silence_stdout()
        return EXIT_BROKEN_PIPE
    except OSError as exc:
        silence_stdout()
        with contextlib.suppress(OSError, ValueError):
            print(f"{prog}: error: cannot write standard output: {os_reason(exc)}", file=sys.stderr, flush=True)
        return EXIT_IO_ERROR
    return 0


def check_output_dir(path, what: str = "--out") -> Path:
    """``path`` created if missing, refused (OutputPathError) if it exists and is not a directory or
    cannot be written in."""
    path = Path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        if isinstance(exc, NotADirectoryError):
            raise OutputPathError(f"{what} {path}: cannot write there: a parent is not a directory") from None
        raise OutputPathError(f"{what} {path}: cannot be checked: {os_reason(exc)}") from None
    if st is not None and not stat.S_ISDIR(st.st_mode):
        kind = "a regular file" if stat.S_ISREG(st.st_mode) else file_kind(st.st_mode)
        raise OutputPathError(f"{what} {path}: exists and is {kind}, not a directory")
    _probe_dir(path, what, path)
    return path


_serial = itertools.count()


def _temporary(dest: Path, tag: str = "tmp") -> tuple[Path, int]:
    """A new file beside ``dest`` (created exclusively, never through a symlink), with ``dest``'s
    suffix (numpy and matplotlib read the format from it) and its permission bits if it exists
    (else 0o666 less the umask): (path, open descriptor)."""
    while True:
        tmp = dest.with_name(f".{dest.stem}.{os.getpid()}-{next(_serial)}.{tag}{dest.suffix}")
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o666)
            break
        except FileExistsError:
            continue
    with contextlib.suppress(OSError):
        os.chmod(fd, stat.S_IMODE(os.stat(dest).st_mode))
    return tmp, fd


def _fsync_dir(directory: Path) -> None:
    """Make a rename in ``directory`` durable (where the system allows a directory to be fsynced)."""
    try:
        fd = os.open(directory, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError as exc:
        if exc.errno not in (errno.EINVAL, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EBADF):
            raise
    finally:
        os.close(fd)


def _remove(path: Path) -> None:
    with contextlib.suppress(OSError):
        os.unlink(path)


def atomic_write(path, write, what: str = "output", durable: bool = True) -> Path:
    """``write(tmp)`` to a new file beside ``path`` (``tmp`` keeps ``path``'s suffix), fsynced and
    renamed over ``path`` (over the target of a symlink) once whole; returns ``path``. ``durable=False``
    skips the two fsyncs, for a file whose reader verifies it (a sweep part's checksum): a power loss
    may then leave it cut short, never a half-written file from a failed or killed process.

    A failure removes the temporary file and leaves ``path`` as it was: an I/O error raises
    :class:`OutputWriteError` naming ``path``; ``path`` turned into something other than a regular
    file meanwhile raises :class:`OutputPathError`; anything else (an interrupt) propagates as is."""
    path = Path(path)
    try:
        _refuse_special(path, what)
        dest = _target(path)
        dest.parent.mkdir(parents=True, exist_ok=True)
        tmp, fd = _temporary(dest)
    except OSError as exc:
        raise OutputWriteError(path, exc) from None
    try:
        os.close(fd)
        write(tmp)
        if durable:
            fd = os.open(tmp, os.O_RDONLY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)
        _refuse_special(dest, what)  # again, right before the rename: nothing but a regular file is replaced
        os.replace(tmp, dest)
        if durable:
            _fsync_dir(dest.parent)
    except OSError as exc:
        _remove(tmp)
        raise OutputWriteError(path, exc) from None
    except BaseException:
        _remove(tmp)
        raise
    return path


def json_ready(value):
    """``value`` with every non-finite float as None (JSON has no NaN) and numpy scalars and arrays
    as Python numbers and lists, through dicts, lists and tuples."""
    if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):  # a numpy scalar or array
        value = value.tolist()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_ready(v) for v in value]
    return value


def write_json(path, data, what: str = "output") -> Path:
    """``data`` as indented JSON in ``path`` (:func:`json_ready`, then :func:`atomic_write`)."""
    text = json.dumps(json_ready(data), indent=1, allow_nan=False) + "\n"
    return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"), what)


class GrowingOutput:
    """A text file written record by record, each record whole under the final name.

    The header goes to a temporary file beside ``path``; every :meth:`append` writes one record and
    fsyncs it; the first one renames the file over ``path`` (a hard link keeps the file that was
    there), so that from then on a reader, or a process killed outright, sees whole records only.
    :meth:`commit` keeps the new file (and drops the old one); :meth:`rollback`, also done on any I/O
    error (then raised as :class:`OutputWriteError`), puts the old file back, or removes the new one
    where there was none. Where no hard link can be made the file stays under its temporary name
    until :meth:`commit`."""

    def __init__(self, path, header: str, what: str = "output"):
        self.path = Path(path)
        self._backup = self._tmp = None
        self._published = self._closed = False
        try:
            _refuse_special(self.path, what)
            self.dest = _target(self.path)
            self.dest.parent.mkdir(parents=True, exist_ok=True)
            self._tmp, self._fd = _temporary(self.dest)
        except OSError as exc:
            raise OutputWriteError(self.path, exc) from None
        self._what = what
        self._guard(self._write, header)

    def _write(self, text: str) -> None:
        data = memoryview(text.encode("utf-8"))
        while data:
            data = data[os.write(self._fd, data):]

    def _guard(self, action, *args):
        try:
            return action(*args)
        except OSError as exc:
            self.rollback()
            raise OutputWriteError(self.path, exc) from None
        except OutputPathError:
            self.rollback()
            raise

    def append(self, text: str) -> None:
        """Write one record (whole lines), fsync it; the first one shows the file under its name."""
        if self._closed:
            raise ValueError(f"{self.path}: already closed")
        self._guard(self._append, text)

    def _append(self, text: str) -> None:
        self._write(text)
        os.fsync(self._fd)
        if not self._published and self._backup is None:
            self._publish(keep_old=True)

    def _publish(self, keep_old: bool) -> None:
        old = _refuse_special(self.dest, self._what)
        if old is not None and keep_old:
            backup = self.dest.with_name(f".{self.dest.stem}.{os.getpid()}-{next(_serial)}.old{self.dest.suffix}")
            try:
                os.link(self.dest, backup)
            except OSError:  # no hard links here: publish at commit, and the old file stays until then
                self._backup = False
                return
            self._backup = backup
        os.replace(self._tmp, self.dest)
        _fsync_dir(self.dest.parent)
        self._published = True

    def commit(self) -> Path:
        """Keep the new file (renamed over ``path`` if it was not yet) and drop the old one."""
        if self._closed:
            return self.path

        def finish():
            os.fsync(self._fd)
            if not self._published:
                self._publish(keep_old=False)

        self._guard(finish)
        self._closed = True
        os.close(self._fd)
        if self._backup:
            _remove(self._backup)
        return self.path

    def rollback(self) -> None:
        """Put back the file that was under ``path`` (or remove the new one); idempotent."""
        if self._closed:
            return
        self._closed = True
        with contextlib.suppress(OSError):
            os.close(self._fd)
        if not self._published:  # the old file never left: only the new one and its link to the old go
            _remove(self._tmp)
            if self._backup:
                _remove(self._backup)
        elif self._backup:
            try:
                os.replace(self._backup, self.dest)
            except OSError:
                _remove(self._backup)
        else:
            _remove(self.dest)
