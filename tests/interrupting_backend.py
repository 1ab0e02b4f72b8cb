"""A sweep back end that is interrupted on purpose, for the tests of interrupted and resumed sweeps."""
from __future__ import annotations

from restitution.sweep.backends import PackageBackend


class InterruptingBackend(PackageBackend):
    """The package back end raising KeyboardInterrupt (as Ctrl-C would) on its n-th chunk (never: 0)."""

    def __init__(self, n):
        super().__init__()
        self.n, self.calls = n, 0

    def evaluate(self, *args):
        self.calls += 1
        if self.calls == self.n:
            raise KeyboardInterrupt
        return super().evaluate(*args)
