"""The native code on Windows, run under Wine (Windows' C runtime maths differ from glibc's in the last
bits: every comparison uses the per-case tolerances of restitution.agreement, from each output's
conditioning, never bit identity).

* The physics: the same stdin/stdout driver as the sanitizer test of tests/fmu/test_native_physics.py,
  built with x86_64-w64-mingw32-gcc (static runtime) or, where mingw-w64 is missing, with zig (the
  compiler the build then uses for the FMUs' Windows DLLs), against restitution.impact.
* The FMU, FMI 2.0 and FMI 3.0: binaries/win64/SpherePlateImpact.dll of the native SpherePlateImpact.fmu
  and binaries/x86_64-windows/SpherePlateImpact.dll of fmi3/SpherePlateImpact.fmu (as built by
  ``python -m restitution.fmu build``), loaded with LoadLibrary by the plain C host of the other host
  tests (tests/c_host/fmi_script_host.c, built for the FMU's version) cross-compiled with mingw-w64 (or
  zig), and the same host built with gcc on the FMU's Linux binary: the same script of FMI calls on both,
  every output compared; one refused value (NaN) is an error status with a log message, not a crash;
  no Python in either process. Co-simulation and model exchange (the same outputs after set_time, the
  parameters set in event mode).
* BouncingBall as model exchange, FMI 2.0 and FMI 3.0: integrated by the host's own solver (Heun steps,
  contacts as bisected state events) under Wine and on Linux, each against the closed-form free-fall
  contact times, and the two against each other within the event location's conditioning.

Needs a Windows C compiler, Debian's gcc-mingw-w64-x86-64 or zig (pip install ziglang; the DLLs are then
zig's too: the tests run whichever the build wrote), and wine64 (+ wine for the ``wine`` command; bash
build_scripts/system_packages.sh installs them); skips saying which is missing. Marked slow: the first
Wine start creates a prefix (~5-30 s), shared by the tests of this file. Every Wine run is a child
process with a timeout and its exit code is asserted.
"""
from __future__ import annotations

import math
import os
import shutil
import subprocess
import zipfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import restitution as r
from restitution.agreement import disagreements, tolerances
from restitution.fmu.builders import toolchains
from restitution.fmu.builders.compile import CFLAGS, prepare_sources

from cases import FMU_FLAGS, FMU_REALS, NAMES, params_for, random_cases
from script_host import ball_me_script, ball_run, build_host, check_ball_run, interface

MINGW = "x86_64-w64-mingw32-gcc"


def _windows_compiler():
    """(the compiler of Windows programs here: mingw-w64 where on PATH, else zig; or None, why not)."""
    try:
        return toolchains.compiler("x86_64-windows"), None
    except toolchains.ToolchainMissing as exc:
        return None, str(exc)


WINDOWS_CC, NO_WINDOWS_CC = _windows_compiler()
WINE = shutil.which("wine64") or shutil.which("wine") or (
    "/usr/lib/wine/wine64" if os.access("/usr/lib/wine/wine64", os.X_OK) else None)
PHYSICS_DRIVER = Path(__file__).resolve().parents[1] / "c_host" / "physics_driver.c"
MODEL = "SpherePlateImpact"
REALS = ("e", "v_rebound", "e_ep", "V_c", "V_star", "eps_y", "e_ze", "lam", "tau0", "T", "t_contact", "m_a",
         "m_eff", "v_plate")
FLAGS = ("plasticity_used", "plate_waves_used", "lambda_in_range", "vstar_in_range", "e_negative", "valid")

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(WINDOWS_CC is None, reason=f"no Windows C compiler: {NO_WINDOWS_CC}"),
    pytest.mark.skipif(WINE is None, reason="wine64 missing (Debian: wine64)"),
]


@pytest.fixture(scope="module")
def wine_env(tmp_path_factory):
    """One Wine prefix for the tests of this file (its creation is most of Wine's start-up time); its
    wineserver (started by these tests, for this prefix only) is stopped at the end."""
    prefix = tmp_path_factory.mktemp("wineprefix")
    env = dict(os.environ, WINEPREFIX=str(prefix), WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=")
    yield env
    server = shutil.which("wineserver")
    if server:
        subprocess.run([server, "-k"], env=env, capture_output=True, timeout=60)



def _unpacked_with_dll(built_fmus, folder, model, tmp_path):
    """(script_host.Interface, unpacked directory) of the native ``folder``/``model``.fmu, skipping where
    it or its Windows binary was not built here."""
    fmu_path = built_fmus / folder / f"{model}.fmu"
    if not fmu_path.is_file():
        pytest.skip(f"{folder}/{model}.fmu not built here (needs gcc)")
    fmu = interface(fmu_path)
    windows_dir = fmu.binary_dirs[1]
    unpacked = tmp_path / "fmu"
    with zipfile.ZipFile(fmu_path) as z:
        z.extractall(unpacked)
    if not (unpacked / "binaries" / windows_dir / f"{model}.dll").is_file():
        pytest.skip(f"the {folder} FMU has no {windows_dir} binary (no Windows compiler when it was built)")
    return fmu, unpacked

def test_win64_physics_under_wine_equals_the_package(tmp_path, wine_env):
    src = prepare_sources(tmp_path / "src")
    shutil.copyfile(PHYSICS_DRIVER, src / "driver.c")
    exe = tmp_path / "driver.exe"
    static = ["-static", "-static-libgcc"] if WINDOWS_CC.name == MINGW else []
    subprocess.run([*WINDOWS_CC.command, *CFLAGS, "-D__USE_MINGW_ANSI_STDIO=1", *static, "-o", str(exe),
                    str(src / "driver.c"), str(src / "rst_physics.c")], check=True, capture_output=True, text=True,
                   env=WINDOWS_CC.env)
    rng = np.random.default_rng(64)
    v, params = random_cases(rng, 60)
    cases, lines = [], []
    for i in range(len(v)):
        m, z, p, w = 1 + i % 2, 1 + i % 3, i % 3, (i // 3) % 3
        case = [v[i]] + [params[n][i] for n in NAMES]
        cases.append((case, (m, z, p, w)))
        lines.append(" ".join(repr(float(x)) for x in case) + f" {m} {z} {p} {w} 1e-06 1e-10")
    run = subprocess.run([WINE, str(exe)], input="\n".join(lines) + "\n", capture_output=True, text=True,
                         timeout=300, env=wine_env)
    assert run.returncode == 0, run.stderr[-2000:]
    outputs = [line for line in run.stdout.splitlines() if line.strip()]
    assert len(outputs) == len(cases), run.stdout[-2000:]
    for (case, (m, z, p, w)), line in zip(cases, outputs):
        fields = line.split()
        assert int(fields[0]) == 0, line
        options = dict(restitution_model=r.RESTITUTION_MODELS[m - 1], zener_method=r.ZENER_METHODS[z - 1],
                       plasticity=r.EFFECT_MODES[p], plate_waves=r.EFFECT_MODES[w])
        got = {name: float.fromhex(x) if x not in ("inf", "nan") else float(x) for name, x in zip(REALS, fields[1:15])}
        got.update((name, bool(int(x))) for name, x in zip(FLAGS, fields[15:]))
        p_case = dict(zip(NAMES, case[1:]))
        tol, flips = tolerances(case[0], p_case, **options)
        problems = disagreements(type("R", (), got), r.impact(case[0], **p_case, **options), tol, flips)
        assert not problems, f"{options}: {problems}"
    assert math.isfinite(float.fromhex(outputs[0].split()[1]))


# --- the native FMU's win64 DLL in a plain C host under Wine ----------------------------------------
FMU_PAIRS = ("s2/al6061", "T4-A1", "glass/glass", "nu0/nu0.499")
FMU_T_OVER_D = (0.05, 1.0, 100.0)
FMU_SPEEDS = (0.0, 1e-6, 1e-3, 0.5, 2.3, 30.0, 1e3)
STEP = 1e-3  # [s] communication step of the script (the impact FMU does not depend on time)


@pytest.fixture(scope="module")
def script_hosts(tmp_path_factory):
    """tests/c_host/fmi_script_host.c built for each FMI version, for Linux with gcc and for win64 with
    mingw-w64 or zig: {version: (linux, win)}."""
    if shutil.which("gcc") is None:
        pytest.skip("gcc missing: the Linux build of the host is the reference")
    out = tmp_path_factory.mktemp("script_host")
    return {v: (build_host(out / f"fmi{v}_script_host", v),
                build_host(out / f"fmi{v}_script_host.exe", v, MINGW if WINDOWS_CC.name == MINGW else WINDOWS_CC))
            for v in (2, 3)}


def _windows_path(path: Path) -> str:
    """A Linux path as Wine's Z: drive (the whole file system in a new prefix) sees it."""
    return "Z:" + str(path.resolve()).replace("/", "\\")


def _fmu_cases():
    """(settings by FMU name, package options) per group of FMU_SPEEDS, covering pairs, t/d, both
    models, the three C Zener methods and the nine effect-mode pairs."""
    cases = []
    for i, (pair, t_over_d, method, model) in enumerate(
            (p, t, z, m) for p in FMU_PAIRS for t in FMU_T_OVER_D for z in (1, 2, 3) for m in (1, 2)):
        plasticity, plate_waves = i % 3, (i // 3) % 3
        params = params_for(pair, t_over_d)
        settings = {name.replace("_", ".", 1): float(value) for name, value in params.items()}
        settings.update(zener_method=method, restitution_model=model, plasticity=plasticity, plate_waves=plate_waves)
        options = dict(zener_method=r.ZENER_METHODS[method - 1], restitution_model=r.RESTITUTION_MODELS[model - 1],
                       plasticity=r.EFFECT_MODES[plasticity], plate_waves=r.EFFECT_MODES[plate_waves])
        cases.append(((pair, t_over_d), params, settings, options))
    return cases


def _fmu_script(fmu, cases, me=False):
    """The FMI calls both hosts make: parameters, then v_approach / doStep / every output, case by
    case; at the end one refused value (plate.t = NaN), a read, a step, terminate and free. As model
    exchange (``me``): the instance starts in continuous-time mode, each case's parameters are set in
    event mode (enter_event, set, update_discrete, enter_ct), and set_time takes the place of doStep."""
    vr = fmu.vr
    script = fmu.me_start(0, "impact") if me else ["instantiate impact", "setup 0 0.0", "enter_init 0", "exit_init 0"]
    t = 0.0
    reals, flags = " ".join(str(vr[n]) for n in FMU_REALS), " ".join(str(vr[n]) for n in FMU_FLAGS)
    for _label, _params, settings, _options in cases:
        script += ["enter_event 0"] if me else []
        for name, value in settings.items():
            script.append(fmu.set(0, name, value))
        script += ["update_discrete 0", "enter_ct 0"] if me else []
        for v in FMU_SPEEDS:
            script += [f"set_real 0 {vr['v_approach']} {v!r}", f"set_time 0 {t + STEP!r}" if me else f"step 0 {t!r} {STEP!r}",
                       f"get_real 0 {reals}", f"get_boolean 0 {flags}"]
            t += STEP
    script += ["enter_event 0"] if me else []
    script += [f"set_real 0 {vr['plate.t']} nan", f"get_real 0 {reals}", f"get_boolean 0 {flags}",
               f"set_time 0 {t + STEP!r}" if me else f"step 0 {t!r} {STEP!r}", "terminate 0", "free 0"]
    return script


def _run_script_host(cmd, script, env=None):
    """Run one host build (a child process with a timeout); its statuses, values and log lines."""
    proc = subprocess.run(cmd, input="\n".join(script) + "\n", capture_output=True, text=True, timeout=600, env=env)
    out = SimpleNamespace(returncode=proc.returncode, stdout=proc.stdout, stderr=proc.stderr, statuses=[],
                          values=[], logs=[], libpython=None)
    for line in proc.stdout.splitlines():
        head, _, rest = line.partition(" ")
        if head == "STATUS":
            out.statuses.append(tuple(rest.split()))
        elif head == "REAL":
            out.values.append(float(rest.split()[2]))
        elif head == "BOOLEAN":
            out.values.append(bool(int(rest.split()[2])))
        elif head == "LOG":
            out.logs.append(rest)
        elif head == "LIBPYTHON":
            out.libpython = rest.strip() == "1"
    return out


def _groups(values, n_groups):
    """Split the values read, in script order, into one ImpactResult-like record per group of speeds."""
    per_read = len(FMU_REALS) + len(FMU_FLAGS)
    records = []
    for g in range(n_groups):
        rows = [values[(g * len(FMU_SPEEDS) + k) * per_read:(g * len(FMU_SPEEDS) + k + 1) * per_read]
                for k in range(len(FMU_SPEEDS))]
        fields = {field: np.array([row[i] for row in rows], dtype=float) for i, field in enumerate(FMU_REALS.values())}
        fields.update({field: np.array([row[len(FMU_REALS) + i] for row in rows], dtype=bool)
                       for i, field in enumerate(FMU_FLAGS.values())})
        records.append(SimpleNamespace(**fields))
    return records


@pytest.mark.parametrize("interface_type", ["cs", "me"])
@pytest.mark.parametrize("folder", ["fmi2", "fmi3"])
def test_win64_fmu_dll_under_wine_equals_the_linux_fmu(built_fmus, folder, interface_type, script_hosts, wine_env,
                                                       tmp_path):
    """The Windows DLL of the native FMU (FMI 2.0: binaries/win64/, FMI 3.0: binaries/x86_64-windows/) in a
    mingw- (or zig-) built C host under Wine and its Linux binary in the same host built with gcc, driven by the same
    script, as co-simulation (``cs``) and as model exchange (``me``: parameters set in event mode, the
    outputs read in continuous-time mode after set_time): every call OK but the refused NaN (an error status, logged, nothing crashes, the previous value
    kept); all 17 outputs of 504 evaluations agree within restitution.agreement's tolerances; Green
    (2022)'s checkpoint (V_c = 0.0265 m/s, V* = 86.9 at 2.3 m/s) on Windows.

    Why a tolerance and not bit identity, though both binaries come from the same C sources with the same
    flags: the DLL calls Windows' C runtime maths (mingw-w64's exp, log, pow, ...) and the .so glibc's;
    both are faithfully rounded but not the same functions, so results may differ in the last bits,
    amplified by each output's conditioning. The tolerance is therefore the per-case bound of
    restitution.agreement (32 ulps x (1 + the output's summed log-sensitivity to the inputs)), the same
    one every comparison between two correct evaluations of the model uses."""
    fmu, unpacked = _unpacked_with_dll(built_fmus, folder, MODEL, tmp_path)
    linux_host, win_host = script_hosts[fmu.version]
    linux_dir, windows_dir = fmu.binary_dirs
    dll = unpacked / "binaries" / windows_dir / f"{MODEL}.dll"
    assert (unpacked / "binaries" / linux_dir / f"{MODEL}.so").is_file()
    guid = fmu.token
    cases = _fmu_cases()
    script = _fmu_script(fmu, cases, me=interface_type == "me")

    # each host loads binaries/<platform>/SpherePlateImpact.<so|dll> of the unpacked FMU and passes it the
    # percent-encoded file: URI of its resources (under Wine: file:///Z:/...)
    linux = _run_script_host([str(linux_host), str(unpacked), MODEL, guid], script)
    win = _run_script_host([WINE, str(win_host), _windows_path(unpacked), MODEL, guid], script, env=wine_env)
    n_reads = len(cases) * len(FMU_SPEEDS) + 1
    for name, run in (("linux64", linux), ("win64 under Wine", win)):
        assert run.returncode == 0, f"{name}: exit {run.returncode}\n{run.stdout[-2000:]}\n{run.stderr[-2000:]}"
        assert run.stdout.rstrip().endswith("DONE"), f"{name}: {run.stdout[-2000:]}"
        assert run.stdout.startswith("INFO 2.0 default" if fmu.version == 2 else "INFO 3.0 "), run.stdout[:200]
        bad = [s for s in run.statuses if s[2] != "OK"]
        assert bad == [("set_real", "0", "Error")], f"{name}: {bad[:10]}"
        assert any(line.startswith("impact Error") and "plate.t = nan is outside the allowed range" in line
                   for line in run.logs), f"{name}: {run.logs[-5:]}"
        assert len(run.values) == n_reads * (len(FMU_REALS) + len(FMU_FLAGS)), name
        assert run.libpython is False, f"{name}: a Python library is loaded in the native FMU's process"
    # the refused value changed nothing: the last read equals the read before it (same platform)
    per_read = len(FMU_REALS) + len(FMU_FLAGS)
    for run in (linux, win):
        assert run.values[-per_read:] == run.values[-2 * per_read:-per_read]

    speeds = np.array(FMU_SPEEDS)
    win_groups, linux_groups = _groups(win.values, len(cases)), _groups(linux.values, len(cases))
    differing, checkpoint_seen = 0, False
    for (label, params, _settings, options), w, lin in zip(cases, win_groups, linux_groups):
        tol, flips = tolerances(speeds, params, **options)
        problems = disagreements(w, lin, tol, flips)
        assert not problems, f"{label} {options}: {problems}"
        differing += sum(int(np.sum(getattr(w, f) != getattr(lin, f))) for f in FMU_REALS.values())
        if label == ("s2/al6061", 1.0) and options["zener_method"] == "exact" and options["restitution_model"] == "e45":
            k = FMU_SPEEDS.index(2.3)
            assert w.V_c[k] == pytest.approx(0.0265, abs=5e-5) and w.V_star[k] == pytest.approx(86.9, abs=0.05)
            checkpoint_seen = True
    assert checkpoint_seen
    total = len(cases) * len(FMU_SPEEDS) * len(FMU_REALS)
    print(f"{folder} {interface_type}: {windows_dir} vs {linux_dir}: {differing} of {total} real outputs differ in some bit, all within "
          "tolerance")


@pytest.mark.parametrize("dt, tol", [(1e-3, 1e-10), (1e-4, 0.0)], ids=["bisected", "step"])
@pytest.mark.parametrize("folder", ["fmi2", "fmi3"])
def test_win64_ball_model_exchange_under_wine_equals_the_linux_fmu(built_fmus, folder, dt, tol, script_hosts,
                                                                   wine_env, tmp_path):
    """BouncingBall's Windows DLL as model exchange, integrated by the host's own solver (fmi_script_host.c:
    integrate, Heun steps of ``dt``, each contact a state event bisected to ``tol``, or located to the step
    without bisection) in the mingw- (or zig-) built host under Wine, and its Linux binary in the gcc-built host.
    Each run on its own: every call OK, the 8 contacts at the closed-form free-fall times
    (script_host.check_ball_run: no earlier than the exact crossing, no later than the resolution carried
    through the flights), the ball at rest with the indicator held. Then the two against each other.

    The tolerance between them, and why: both hosts do the same IEEE double arithmetic on the same script
    (Heun's combinations, the bisection's midpoints), and the ball's model-exchange path in the FMU
    (der(h) = v, der(v) = -g, the indicator h, the rebound v -> e v and the rest test) calls no function of
    the C runtime's maths library, so the runs will usually agree to the bit; but the DLL and the .so are
    different binaries with different C runtimes, and nothing here relies on bit identity. Where a
    last-bit difference matters is the event location: h at a bisection midpoint within rounding of 0 may
    take the other branch, which moves that contact by up to the resolution and every later one by what
    that adds to the flights. That is exactly the conditioning located_contact_bounds gives, so the
    contact times may differ by the bound of each contact (and the last approach speed by its excess
    bound), no more; the states at rest are 0 and the indicator 1 m exactly on both."""
    fmu, unpacked = _unpacked_with_dll(built_fmus, folder, "BouncingBall", tmp_path)
    linux_host, win_host = script_hosts[fmu.version]
    linux_dir, windows_dir = fmu.binary_dirs
    script = ball_me_script(fmu, dt, tol)
    linux = _run_script_host([str(linux_host), str(unpacked), "BouncingBall", fmu.token], script)
    win = _run_script_host([WINE, str(win_host), _windows_path(unpacked), "BouncingBall", fmu.token], script,
                           env=wine_env)
    runs = {}
    for name, run in (("linux", linux), ("win64 under Wine", win)):
        assert run.returncode == 0, f"{name}: exit {run.returncode}\n{run.stdout[-2000:]}\n{run.stderr[-2000:]}"
        assert run.libpython is False, name
        runs[name] = ball_run(run.stdout)
        delays, excess = check_ball_run(runs[name], dt, tol)
    lin, w = runs["linux"], runs["win64 under Wine"]
    for k, (a, b, late) in enumerate(zip(w.contacts, lin.contacts, delays)):
        assert abs(a - b) <= late, (k, a, b, late)
    assert abs(w.v_impact - lin.v_impact) <= excess[-1]
    assert w.vectors == lin.vectors and w.impacts == lin.impacts and w.at_rest == lin.at_rest
    differing = sum(a != b for a, b in zip(w.contacts, lin.contacts))
    print(f"{folder} ME dt={dt} tol={tol}: {differing} of {len(lin.contacts)} contact times differ in some bit")
