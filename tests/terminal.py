"""Run a command with its stderr on a pseudo-terminal, as a user at a terminal would see it."""
from __future__ import annotations

import os
import subprocess


def with_terminal_stderr(cmd, env, cwd=None, timeout: float = 300):
    """(exit status, stdout, stderr) of ``cmd`` with stderr on an 80-column pseudo-terminal."""
    import fcntl
    import pty
    import struct
    import termios

    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 80, 0, 0))
    proc = subprocess.Popen([str(c) for c in cmd], stdout=subprocess.PIPE, stderr=slave, stdin=subprocess.DEVNULL,
                            text=True, env=env, cwd=cwd)
    os.close(slave)
    chunks = []
    while True:
        try:
            data = os.read(master, 65536)
        except OSError:  # EIO: the child closed the terminal
            break
        if not data:
            break
        chunks.append(data)
    out = proc.stdout.read()
    proc.wait(timeout=timeout)
    os.close(master)
    return proc.returncode, out, b"".join(chunks).decode("utf-8", "replace")


def takes_ctrl_c() -> None:
    """``preexec_fn`` of a child that a test interrupts as a terminal's Ctrl-C would: SIGINT back to its
    default action. A shell starts a background job (``cmd &``, a CI step run that way) with SIGINT
    ignored, and an ignored signal stays ignored across exec: the child would then never see the test's
    SIGINT and run to its end."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)
