"""The native backend (rst_native_impact.c) maps the FMU's generated interface table onto the C physics:
every output the interface declares is written, from the right inputs, with the package's values.

Compiled with the generated headers (restitution.fmu.describe.c_header.c_header, the Zener table) into a
shared library and driven through ctypes on a value store indexed by value reference, as the C
front drives it. Values are compared with restitution.agreement's per-case tolerances (conditioning),
never bit for bit.
"""
from __future__ import annotations

import ctypes
import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import restitution as r
from restitution.agreement import disagreements, tolerances
from restitution.fmu.describe.c_header import variables
from restitution.model import published
from restitution.fmu.builders.native import write_backend
from restitution.fmu.builders.compile import CFLAGS, prepare_sources

from cases import FMU_FLAGS, FMU_REALS, NAMES, random_cases

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is needed to compile the native backend")

TABLE = {v.name: v for v in variables("SpherePlateImpact")}
HOSTILE_DRIVER = Path(__file__).resolve().parents[1] / "c_host" / "hostile_store_values.c"


@pytest.fixture(scope="module")
def backend(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("backend")
    src = prepare_sources(tmp / "src")
    write_backend("SpherePlateImpact", src)
    lib = tmp / "libbackend.so"
    subprocess.run(["gcc", *CFLAGS, "-fPIC", "-shared", "-o", str(lib), str(src / "rst_native_impact.c"),
                    str(src / "rst_physics.c"), "-lm"], check=True, capture_output=True, text=True)
    so = ctypes.CDLL(str(lib))
    so.rst_impact_evaluate.argtypes = (ctypes.POINTER(ctypes.c_double), ctypes.c_char_p, ctypes.c_size_t)
    return so



#: A value no output ever takes: what the store holds before an evaluation, so a slot it leaves shows.
SENTINEL = -7.25e301


def evaluate(backend, values: dict):
    store = (ctypes.c_double * len(TABLE))(*([SENTINEL] * len(TABLE)))
    for v in TABLE.values():
        if v.causality in ("parameter", "input"):
            store[v.vr] = float(values.get(v.name, v.start))
    message = ctypes.create_string_buffer(512)
    status = backend.rst_impact_evaluate(store, message, 512)
    computed = {v.name: store[v.vr] for v in TABLE.values() if v.causality in ("output", "calculatedParameter")}
    return status, computed, message.value.decode()


@pytest.mark.parametrize("values", [{}, {"zener_method": 4}, {"zener_method": 3, "v_approach": 1e4}],
                         ids=["ok", "refused", "endless-contact"])
def test_every_output_of_the_interface_is_written(backend, values):
    """Whether the evaluation succeeds or fails, every output slot of the store is overwritten, and the
    outputs are exactly those the tests know (FMU_REALS, FMU_FLAGS)."""
    _status, out, _message = evaluate(backend, values)
    assert [name for name, value in out.items() if value == SENTINEL] == []
    used = {v.name for v in TABLE.values() if v.causality == "calculatedParameter"}
    assert set(FMU_REALS) | set(FMU_FLAGS) | used == set(out)


@pytest.mark.parametrize("method", [1, 2, 3])
def test_values_through_the_interface_equal_the_package(backend, method):
    rng = np.random.default_rng(100 + method)
    v, params = random_cases(rng, 150)
    for i in range(len(v)):
        model, plasticity, plate_waves = int(rng.integers(1, 3)), int(rng.integers(0, 3)), int(rng.integers(0, 3))
        fmu_values = {"v_approach": v[i], **{n.replace("_", ".", 1): params[n][i] for n in NAMES},
                      "restitution_model": model, "zener_method": method, "plasticity": plasticity,
                      "plate_waves": plate_waves}
        status, out, message = evaluate(backend, fmu_values)
        assert status == 0, message
        options = dict(restitution_model=r.RESTITUTION_MODELS[model - 1], zener_method=r.ZENER_METHODS[method - 1],
                       plasticity=r.EFFECT_MODES[plasticity], plate_waves=r.EFFECT_MODES[plate_waves])
        case = {n: params[n][i] for n in NAMES}
        expected = type("R", (), published(r.impact(v[i], **case, **options).as_dict()))
        got = type("R", (), {**{FMU_REALS[k]: out[k] for k in FMU_REALS},
                              **{FMU_FLAGS[k]: bool(out[k]) for k in FMU_FLAGS}})
        tol, flips = tolerances(v[i], case, **options)
        problems = disagreements(got, expected, tol, flips)
        assert not problems, f"case {i} {options}: {problems}"


def test_a_cache_kept_across_speeds_gives_the_package_values(backend):
    """rst_impact_evaluate_cached with one cache per parameter set (all zero: stale, so the first call fills
    it) and the speed changed in the store between calls, as the FMU steps: every output is the package's,
    within each output's conditioning (the cached terms are the parameters' and nothing else)."""
    backend.rst_impact_evaluate_cached.argtypes = (ctypes.c_void_p, ctypes.POINTER(ctypes.c_double), ctypes.c_char_p,
                                                   ctypes.c_size_t)
    rng = np.random.default_rng(77)
    _, params = random_cases(rng, 12)
    speeds = np.concatenate([[0.0], np.geomspace(1e-6, 1e3, 7)])
    for i in range(12):
        case = {n: float(params[n][i]) for n in NAMES}
        method, model = 1 + i % 3, 1 + (i // 3) % 2
        store = (ctypes.c_double * len(TABLE))(*([SENTINEL] * len(TABLE)))
        for v in TABLE.values():
            if v.causality in ("parameter", "input"):
                store[v.vr] = float(v.start)
        for name, value in case.items():
            store[TABLE[name.replace("_", ".", 1)].vr] = value
        store[TABLE["zener_method"].vr], store[TABLE["restitution_model"].vr] = method, model
        cache = ctypes.create_string_buffer(1024)  # zeroed, larger than rst_impact_cache
        message = ctypes.create_string_buffer(512)
        options = dict(restitution_model=r.RESTITUTION_MODELS[model - 1], zener_method=r.ZENER_METHODS[method - 1])
        for v in speeds:
            store[TABLE["v_approach"].vr] = v
            assert backend.rst_impact_evaluate_cached(cache, store, message, 512) == 0, message.value
            got = type("R", (), {**{FMU_REALS[k]: store[TABLE[k].vr] for k in FMU_REALS},
                                  **{FMU_FLAGS[k]: bool(store[TABLE[k].vr]) for k in FMU_FLAGS}})
            expected = type("E", (), published(r.impact(v, **case, **options).as_dict()))
            problems = disagreements(got, expected, *tolerances(v, case, **options))
            assert not problems, f"case {i}, v = {v}, {options}: {problems}"


def test_defaults_are_the_paper_checkpoint(backend):
    """The interface's start values (S2 tool steel on Al 6061) at 2.3 m/s: V_c = 0.0265 m/s, V* = 86.9
    (Green 2022, Sec. 7)."""
    status, out, _ = evaluate(backend, {"v_approach": 2.3})
    assert status == 0
    assert out["jgm.V_c"] == pytest.approx(0.0265, abs=5e-5) and out["jgm.V_star"] == pytest.approx(86.9, abs=0.05)


def test_ode_is_refused_with_a_message_naming_the_python_fmu(backend):
    status, out, message = evaluate(backend, {"zener_method": 4})
    assert status == 2
    assert "Python FMU" in message and "zener_method = 4" in message
    assert all(math.isnan(out[k]) for k in FMU_REALS) and not any(out[k] for k in FMU_FLAGS)


def test_backends_take_hostile_store_values_under_sanitizers(tmp_path):
    """NaN, infinities, huge, subnormal and fractional values in every input slot of both backends, in
    an ASan + UBSan build (any report aborts) run as a child process: no undefined behaviour (a code
    beyond int is never cast), no hang, no crash. The front rejects such values before they get here;
    this is the backends' own defence (the program: tests/c_host/hostile_store_values.c)."""
    src = prepare_sources(tmp_path / "src")
    write_backend("SpherePlateImpact", src)
    write_backend("BouncingBall", src)
    exe = tmp_path / "hostile"
    build = subprocess.run(["gcc", *CFLAGS, "-g", "-fsanitize=address,undefined,float-cast-overflow",
                            "-fno-sanitize-recover=all", "-I", str(src), "-o", str(exe), str(HOSTILE_DRIVER),
                            *(str(src / f) for f in ("rst_native_impact.c", "rst_native_ball.c", "rst_physics.c")),
                            "-lm"],
                           capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120, env={"PATH": "/usr/bin:/bin"})
    assert run.returncode == 0 and run.stdout.startswith("done"), run.stdout + run.stderr[-3000:]
    assert "runtime error" not in run.stderr, run.stderr[-3000:]
