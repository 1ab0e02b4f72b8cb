"""Ctrl-C for hosts of pythonfmu FMUs: held back while an FMU call runs, raised between calls."""
from __future__ import annotations

import signal
import threading

__all__ = ["DeferredInterrupt"]


class DeferredInterrupt:
    """SIGINT held back while the FMU runs: the handler only notes it, and the master raises
    KeyboardInterrupt between FMU calls (:meth:`check`). A KeyboardInterrupt raised inside a
    pythonfmu FMU's callback would end as fmi2Fatal and lose the drop in progress and the instance;
    a second Ctrl-C interrupts at once. Only in the main thread (elsewhere signals are not ours)."""

    def __init__(self):
        self.pending = False
        self.previous = None

    def __enter__(self):
        if threading.current_thread() is threading.main_thread() and \
                signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            self.previous = signal.signal(signal.SIGINT, self._note)
        return self

    def _note(self, signum, frame):
        if self.pending:  # the second Ctrl-C: at once
            raise KeyboardInterrupt
        self.pending = True

    def check(self):
        if self.pending:
            raise KeyboardInterrupt

    def __exit__(self, *exc):
        if self.previous is not None:
            signal.signal(signal.SIGINT, self.previous)
