"""Ctrl-C for hosts of pythonfmu FMUs: held back while an FMU call runs, raised between calls."""
from __future__ import annotations

import signal
import threading

__all__ = ["DeferredInterrupt", "forget_unhandled_interrupt"]


class DeferredInterrupt:
    """SIGINT held back while the FMU runs: the handler only notes it, and the master raises
    KeyboardInterrupt between FMU calls (:meth:`check`). A KeyboardInterrupt raised inside a
    pythonfmu FMU's callback would end as fmi2Fatal and lose the drop in progress and the instance;
    a second Ctrl-C interrupts at once. Only in the main thread (elsewhere signals are not ours).

    By default it takes Ctrl-C over only from Python's own handler; ``over_any_handler=True`` takes it
    over from any Python handler (another DeferredInterrupt's included) for a step that must not be
    cut in two, such as writing a finished chunk and recording it as done."""

    def __init__(self, over_any_handler: bool = False):
        self.pending = False
        self.previous = None
        self.over_any_handler = over_any_handler

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            current = signal.getsignal(signal.SIGINT)
            if current is signal.default_int_handler or (self.over_any_handler and callable(current)):
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


def forget_unhandled_interrupt() -> None:
    """Clear CPython's note that a KeyboardInterrupt went unhandled, for a command line that handled its
    Ctrl-C and returns its own status (130).

    A KeyboardInterrupt raised inside code run by ``exec`` of a string sets that note even when a caller
    catches it: a dataclass or namedtuple being made while a module imports (distributed's, when a sweep
    was interrupted as its cluster started). At exit the interpreter then killed itself with SIGINT
    (status -2) instead of returning 130, in 4 of 12 such runs. Every ``exec`` of a string that
    completes clears the note first (measured on CPython 3.11; the note is not otherwise reachable)."""
    exec("pass")
