"""The native backend (rst_native_impact.c) maps the FMU's generated interface table onto the C physics:
every output the interface declares is written, from the right inputs, with the package's values.

Compiled with the generated headers (restitution.fmu.interface.c_header, the Zener table) into a
shared library and driven through ctypes on a value store indexed by value reference, as the C
front drives it. Values are compared with restitution.agreement's per-case tolerances (conditioning),
never bit for bit.
"""
from __future__ import annotations

import ctypes
import math
import shutil
import subprocess

import numpy as np
import pytest

import restitution as r
from restitution.agreement import disagreements, tolerances
from restitution.fmu.interface import variables
from restitution.model import published
from restitution.fmu.native.build_native import write_backend
from restitution.fmu.native.compile import CFLAGS, prepare_sources

from test_hard_cases import FMU_FLAGS, FMU_REALS
from test_native_physics import NAMES, random_cases

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is needed to compile the native backend")

TABLE = {v.name: v for v in variables("SpherePlateImpact")}
#: rst_impact_binding's array lengths: the interface's inputs and parameters, and its outputs
N_IN = sum(v.causality != "output" for v in TABLE.values())
N_OUT = sum(v.causality == "output" for v in TABLE.values())


class Binding(ctypes.Structure):
    _fields_ = [("n_variables", ctypes.c_size_t), ("input_vr", ctypes.c_uint * N_IN),
                ("output_vr", ctypes.c_uint * N_OUT)]


@pytest.fixture(scope="module")
def backend(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("backend")
    src = prepare_sources(tmp / "src")
    write_backend("SpherePlateImpact", src)
    lib = tmp / "libbackend.so"
    subprocess.run(["gcc", *CFLAGS, "-fPIC", "-shared", "-o", str(lib), str(src / "rst_native_impact.c"),
                    str(src / "rst_physics.c"), "-lm"], check=True, capture_output=True, text=True)
    so = ctypes.CDLL(str(lib))
    so.rst_impact_bind.argtypes = (ctypes.POINTER(Binding), ctypes.c_char_p, ctypes.c_size_t)
    so.rst_impact_evaluate.argtypes = (ctypes.POINTER(Binding), ctypes.POINTER(ctypes.c_double), ctypes.c_char_p,
                                       ctypes.c_size_t)
    binding = Binding()
    message = ctypes.create_string_buffer(512)
    assert so.rst_impact_bind(ctypes.byref(binding), message, 512) == 0, message.value
    return so, binding



def evaluate(backend, values: dict):
    so, binding = backend
    store = (ctypes.c_double * binding.n_variables)()
    for v in TABLE.values():
        if v.causality != "output":
            store[v.vr] = float(values.get(v.name, v.start))
    message = ctypes.create_string_buffer(512)
    status = so.rst_impact_evaluate(ctypes.byref(binding), store, message, 512)
    return status, {v.name: store[v.vr] for v in TABLE.values() if v.causality == "output"}, message.value.decode()


def test_binding_covers_every_output_of_the_interface(backend):
    _so, binding = backend
    outputs = {v.vr for v in TABLE.values() if v.causality == "output"}
    assert binding.n_variables == len(TABLE)
    assert set(binding.output_vr) == outputs
    assert set(FMU_REALS) | set(FMU_FLAGS) == {v.name for v in TABLE.values() if v.causality == "output"}


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


_HOSTILE_DRIVER = r"""
#include <math.h>
#include <stdio.h>
#include "rst_native_impact.h"
#include "rst_native_ball.h"
int main(void)
{
    static const double bad[] = {NAN, INFINITY, -INFINITY, 1e300, -1e300, 0.0, -0.0, 4.9e-324, 2.5, -1.0, 5.0};
    rst_impact_binding b;
    rst_ball_binding bb;
    char message[256];
    double store[64], t = 0.0;
    size_t slot, k, i;
    int failures = 0;
    if (rst_impact_bind(&b, message, sizeof message) || rst_ball_bind(&bb, message, sizeof message)) {
        puts(message);
        return 1;
    }
    for (slot = 0; slot < RST_IMPACT_N_INPUTS; slot++)
        for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
            for (i = 0; i < b.n_variables; i++)
                store[i] = 1.0;
            store[b.input_vr[12]] = 1.0;
            store[b.input_vr[slot]] = bad[k];
            (void)rst_impact_evaluate(&b, store, message, sizeof message);
        }
    for (slot = 0; slot < 5; slot++)
        for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
            for (i = 0; i < bb.n_variables; i++)
                store[i] = 0.0;
            store[bb.vr[RST_BALL_H0]] = 0.3;
            store[bb.vr[RST_BALL_G]] = 9.81;
            store[bb.vr[RST_BALL_V_MIN]] = 0.1;
            store[bb.vr[RST_BALL_CONTACT_MODE]] = 2.0;
            store[bb.vr[RST_BALL_E]] = 0.8;
            store[bb.vr[slot]] = bad[k];
            rst_ball_initialize(&bb, store, 0.0);
            for (t = 0.0, i = 0; i < 200; i++, t += 0.01)
                rst_ball_do_step(&bb, store, t, 0.01);
        }
    printf("done %d\n", failures);
    return 0;
}
"""


def test_backends_take_hostile_store_values_under_sanitizers(tmp_path):
    """NaN, infinities, huge, subnormal and fractional values in every input slot of both backends, in
    an ASan + UBSan build (any report aborts) run as a child process: no undefined behaviour (a code
    beyond int is never cast), no hang, no crash. The front rejects such values before they get here;
    this is the backends' own defence."""
    from restitution.fmu.native.compile import prepare_sources

    src = prepare_sources(tmp_path / "src")
    write_backend("SpherePlateImpact", src)
    write_backend("BouncingBall", src)
    (src / "hostile.c").write_text(_HOSTILE_DRIVER)
    exe = tmp_path / "hostile"
    build = subprocess.run(["gcc", *CFLAGS, "-g", "-fsanitize=address,undefined,float-cast-overflow",
                            "-fno-sanitize-recover=all", "-o", str(exe), *(str(src / f) for f in (
                                "hostile.c", "rst_native_impact.c", "rst_native_ball.c", "rst_physics.c")), "-lm"],
                           capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120, env={"PATH": "/usr/bin:/bin"})
    assert run.returncode == 0 and run.stdout.startswith("done"), run.stdout + run.stderr[-3000:]
    assert "runtime error" not in run.stderr, run.stderr[-3000:]
