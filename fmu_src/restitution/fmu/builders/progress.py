"""The lines a build prints as it goes (stderr, flushed, unless the caller takes them): one when each
product's build starts, a start and an end line (with its seconds) for each platform's compilation, naming
the product, the platform and the compiler (``gcc``, ``zig cc -target <triple>``), and, before zig's first
use in a build, whether zig's cache is warm: zig builds each target's C runtime into it the first time (a
few minutes on two cores, most of it Windows'), which is what makes a first build slow.

    fmu build: fmi2/SpherePlateImpact.fmu   x86_64-linux    gcc ...
    fmu build: fmi2/SpherePlateImpact.fmu   x86_64-linux    gcc: 1.4 s
"""
from __future__ import annotations

import sys
import time
from contextlib import contextmanager

from . import toolchains

__all__ = ["Progress", "stderr_line", "quiet"]

PREFIX = "fmu build: "


def stderr_line(message: str) -> None:
    """``message`` on stderr, at once (a build's lines interleave with the compilers' own output)."""
    print(message, file=sys.stderr, flush=True)


def _quiet(message: str) -> None:
    pass


def _seconds(value: float) -> str:
    return f"{value:.1f} s"


class Progress:
    """Says what a build does as it does it: ``say(line)`` for every line (default :func:`stderr_line`).

    ``zig_targets``: the platforms the whole build compiles with zig (:meth:`expect_zig`), so the line
    before zig's first use can say which of them zig's cache lacks."""

    def __init__(self, say=None, clock=time.monotonic):
        self.say = say if say is not None else stderr_line
        self.clock = clock
        self.zig_targets: list = []
        self.cold: set[str] | None = None  # the zig targets whose C runtime zig's cache lacked; None: unknown
        self._zig_told = False

    def line(self, message: str) -> None:
        self.say(PREFIX + message)

    def expect_zig(self, targets) -> None:
        """The platforms this build will compile with zig (each once)."""
        self.zig_targets = list(dict.fromkeys(targets))

    def zig_notice(self, first) -> None:
        """Before zig's first use (for ``first``), once: whether zig's cache holds the C runtime of every
        target the build compiles with zig, or which it lacks (zig builds them: a few minutes), or that it
        may have to (the cache cannot be read)."""
        if self._zig_told or self.say is _quiet:
            return
        self._zig_told = True
        targets = self.zig_targets or [first]
        if first not in targets:
            targets = [first, *targets]
        cache = toolchains.zig_environment()["ZIG_GLOBAL_CACHE_DIR"]
        cold = toolchains.zig_cache_cold(targets, cache)
        named = cold or targets
        names = ", ".join(t.name for t in named)
        most = ", most of it the Windows C runtime" if any(t.name == "x86_64-windows" for t in named) else ""
        if cold is None:
            self.cold = None
            self.line(f"zig's first use may fill its cache ({cache}): zig builds the C runtime of {names} "
                      f"where it has none yet, a few minutes on two cores{most}")
        elif cold:
            self.cold = {t.name for t in cold}
            self.line(f"zig's first use fills its cache ({cache}), which holds no C runtime yet for {names}: "
                      f"zig builds them, a few minutes on two cores{most}; later builds take seconds")
        else:
            self.cold = set()
            self.line(f"zig's cache ({cache}) is warm: it holds the C runtime of {names}")

    @contextmanager
    def step(self, product: str, platform: str, compiler: str, note: str = ""):
        """A start line, then, when the step is done, the same with its seconds (or "failed after")."""
        head = f"{product:<30} {platform:<15} {compiler}"
        self.line(f"{head} ...{note}")
        start = self.clock()
        try:
            yield
        except BaseException:
            self.line(f"{head}: failed after {_seconds(self.clock() - start)}")
            raise
        self.line(f"{head}: {_seconds(self.clock() - start)}")

    def compile_step(self, product: str):
        """``step(platform, compiler)`` for :func:`toolchains.build_binary`: one platform's compilation of
        ``product``, told as a step (zig's cache line first, before zig's first use)."""
        def step(target, cc):
            note = ""
            if cc.name == "zig cc":
                self.zig_notice(target)
                if self.cold is None or target.name in self.cold:
                    note = " (zig's first build for this target: may take minutes)"
                    if self.cold is not None:
                        self.cold.discard(target.name)
            return self.step(product, target.name, toolchains.compiler_label(target, cc), note)
        return step


def quiet() -> Progress:
    """A build that prints nothing (the builders' default when called on their own)."""
    return Progress(_quiet)
