"""The C physics of the native FMUs (C99, no Python at run time), following the ``restitution``
package (the package is authoritative; tests/fmu/test_native_*.py keep the two together).

* ``rst_physics.h`` / ``rst_physics.c``: JGM Eqs. (1)-(8), Zener Eqs. (9)-(13a), (22), fusion
  Eqs. (17)-(20) of I. Green, Nonlinear Dyn (2022), in the package's well-conditioned forms.
* :mod:`.zener_table_header`: writes the C header with the ``exact`` method's Hermite pieces, generated
  at build time from ``restitution/data/zener_table.npz`` (never edited by hand, never committed).

:mod:`restitution.fmu.builders.compile` compiles it; the tests call it through ctypes (tests/physics_ctypes.py).
"""
