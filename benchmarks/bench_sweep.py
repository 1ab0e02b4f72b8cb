"""Measure design-space sweep throughput and write the table in docs/performance.md.

    .venv/bin/python benchmarks/bench_sweep.py [--no-write] [--fmu-cases N] [--package-cases N]

Builds SpherePlateImpact.fmu from the working tree into a temporary directory, then measures

* the single-call FMU cost: one fmi2SetReal (v_approach and plate.t) and one fmi2GetReal (e) by a
  host in a plain loop, the cheapest way to ask the FMU for one case (no Dask, no table);
* cases per second of the same sweep (S2 steel on Al 6061 and brass on borosilicate glass over
  approach speed x t/d) for the vectorized package and for the FMU back end: serially in this
  process and on LocalClusters of 1 and 2 single-threaded worker processes. Every sweep keeps all
  37 columns (all inputs and outputs) and gathers them to this process, as ``run_sweep`` does by
  default. Worker start-up and the first FMU load are done before timing (reported apart).

Then the goals (benchmarks/sweep_goals.py): sweep / model per case, serially and per
Dask worker, and Parquet write / gather of the table.

Scaling efficiency = rate(2 workers) / (2 x rate(1 worker)). Cost per case: wall time per case
per worker (workers / rate), and CPU time per case, both inside the tasks (building the cases and
evaluating them) and in all processes of the run (this client with the LocalCluster's scheduler,
the nannies and workers: Dask's own overhead and the gathering of the table included); compared
with the single-call CPU cost. The share of the CPUs that *other* processes took during each run
is reported too: on a shared machine the wall-clock rates and the scaling drop, the CPU times do
not. Rates from the fastest of ``--repeats`` runs, CPU times the least of them (anything else on
the machine only adds to them). Well under a minute on 2 cores.
"""
from __future__ import annotations

import argparse
import os
import platform
import re
import sys
import tempfile
import time
from pathlib import Path
from harness import cpu_name

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
DOC = ROOT / "docs" / "performance.md"
BEGIN, END = "<!-- bench_sweep:begin -->", "<!-- bench_sweep:end -->"


def sweep_spec(n_speeds: int, n_ratios: int):
    from restitution.sweep import SweepSpec

    return SweepSpec(pairs=["s2_tool_steel/al_6061", "brass_260/borosilicate_glass"],
                     grid={"v_approach": {"geomspace": [0.05, 20.0, n_speeds]},
                           "t_over_d": {"geomspace": [0.05, 10.0, n_ratios]}})


def single_call_cost(fmu_path, n: int = 20000) -> dict:
    """Microseconds per single FMU call by a host: setReal(v, t) + getReal(e), and the same
    reading all 17 outputs (what a sweep case reads)."""
    import numpy as np
    from restitution.cosim import FmuInstance
    from restitution.sweep.spec import OUTPUTS

    out = {}
    with FmuInstance(fmu_path, instance_name="bench") as fmu:
        s = fmu.slave
        set_vr = [fmu.vr("v_approach"), fmu.vr("plate.t")]
        e_vr = [fmu.vr("e")]
        reals = [fmu.vr(n_) for n_, _f, t in OUTPUTS if t == "Real"]
        bools = [fmu.vr(n_) for n_, _f, t in OUTPUTS if t == "Boolean"]
        v = np.geomspace(0.05, 20.0, n).tolist()
        t = np.geomspace(0.3e-3, 60e-3, n)[::-1].tolist()
        for label, body in (("e", lambda i: s.getReal(e_vr)),
                            ("all", lambda i: (s.getReal(reals), s.getBoolean(bools)))):
            best = cpu_best = float("inf")
            for _ in range(2):
                t0, c0 = time.perf_counter(), time.thread_time()
                for i in range(n):
                    s.setReal(set_vr, [v[i], t[i]])
                    body(i)
                best = min(best, (time.perf_counter() - t0) / n)
                cpu_best = min(cpu_best, (time.thread_time() - c0) / n)
            out[label] = best * 1e6
            out[label + "_cpu"] = cpu_best * 1e6
    return out


class OtherLoad:
    """Share of the machine's CPU that processes other than this one and its children (the Dask
    workers) used while a run lasted: what the rates had to share the cores with."""

    def __enter__(self):
        import psutil

        self._psutil = psutil
        self.t0 = time.perf_counter()
        self.busy0 = self._busy()
        self.ours0 = self._ours()
        return self

    def _busy(self):
        t = self._psutil.cpu_times()  # guest time is already inside user time
        return sum(getattr(t, k, 0.0) for k in ("user", "nice", "system", "irq", "softirq", "steal"))

    def _ours(self):
        me = self._psutil.Process()
        total = sum(me.cpu_times()[:2])
        for child in me.children(recursive=True):
            try:
                total += sum(child.cpu_times()[:2])
            except self._psutil.Error:
                pass
        return total

    def __exit__(self, *exc):
        wall = time.perf_counter() - self.t0
        self.ours = self._ours() - self.ours0
        others = (self._busy() - self.busy0) - self.ours
        self.share = max(0.0, others) / (wall * (os.cpu_count() or 1))


def timed(fn, repeats):
    """The fastest of ``repeats`` runs (its result and the other processes' CPU share during it), and
    the least CPU time of the runs: of all our processes, and inside the tasks. Other processes, the
    allocator or the hypervisor can only add CPU time to a run, so the least is the run's own cost."""
    best, cpu_all, cpu_tasks = None, float("inf"), float("inf")
    for _ in range(repeats):
        with OtherLoad() as load:
            res = fn()
        cpu_all = min(cpu_all, load.ours)
        cpu_tasks = min(cpu_tasks, res.info["cpu_seconds"])
        if best is None or res.elapsed < best[0].elapsed:
            best = (res, load.share)
    return (*best, cpu_all, cpu_tasks)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--no-write", action="store_true", help="print the table, leave docs/performance.md alone")
    parser.add_argument("--fmu-cases", type=int, default=24_000, help="cases of the FMU sweeps (default 24000)")
    parser.add_argument("--package-cases", type=int, default=4_800_000,
                        help="cases of the package sweeps (default 4800000)")
    parser.add_argument("--repeats", type=int, default=5, help="runs of each measurement; the fastest (wall) and the least CPU count")
    parser.add_argument("--goal-cases", type=int, default=1_000_000,
                        help="cases of the sweep / model and write / gather measurements (default 1000000)")
    parser.add_argument("--streamed-cases", type=float, default=1e8,
                        help="cases of the streamed run on a LocalCluster of 2 workers, run after one of a tenth "
                             "of the size (default 1e8: about 2 minutes and 30 GB of temporary disk; 0 skips them)")
    args = parser.parse_args(argv)

    import dask
    import fmpy
    import numpy as np
    from restitution.fmu.builders import build_one
    from restitution.sweep import machine_workers, open_client, release_fmus, run_sweep

    t_all = time.perf_counter()
    load_before = os.getloadavg()[0]
    if load_before > 0.5:
        print(f"warning: load average {load_before:.1f} before the benchmark: other processes share the cores, "
              f"the wall-clock rates and scaling will be low (CPU time per case is not affected)")
    tmp = tempfile.TemporaryDirectory(prefix="bench_sweep_")
    fmu = build_one("SpherePlateImpact", Path(tmp.name))
    single = single_call_cost(fmu)
    print(f"single FMU call: {single['e']:.1f} us (set v, t; get e), {single['all']:.1f} us (get all 17 outputs)")

    ratios = 40
    fmu_spec = sweep_spec(max(1, args.fmu_cases // (2 * ratios)), ratios)
    pkg_spec = sweep_spec(max(1, args.package_cases // (2 * ratios)), ratios)
    warm = sweep_spec(4, 4)
    rows = []

    def record(path, where, workers, best, startup=None):
        res, others, ours, tasks = best
        rows.append(dict(path=path, where=where, workers=workers, cases=len(res), elapsed=res.elapsed,
                         rate=res.cases_per_second, cpu=tasks / len(res) * 1e6,
                         total_cpu=ours / len(res) * 1e6, others=others, startup=startup))
        print(f"{path:8s} {where:22s} {res.summary()}; other processes used {others:.0%} of the CPUs")

    reps = args.repeats
    record("package", "serial (this process)", 1, timed(lambda: run_sweep(pkg_spec, "package", scheduler="serial"), reps))
    run_sweep(warm, "fmu", fmu=fmu, scheduler="serial", release=False)
    record("fmu", "serial (this process)", 1,
           timed(lambda: run_sweep(fmu_spec, "fmu", fmu=fmu, scheduler="serial", release=False), reps))
    release_fmus()
    for workers in (1, 2):
        t0 = time.perf_counter()
        with open_client("local", n_workers=workers) as client:
            cluster_start = time.perf_counter() - t0
            run_sweep(warm, "package", scheduler=client)
            t1 = time.perf_counter()
            run_sweep(warm, "fmu", fmu=fmu, scheduler=client, release=False)
            fmu_start = time.perf_counter() - t1
            record("package", "Dask LocalCluster", workers,
                   timed(lambda: run_sweep(pkg_spec, "package", scheduler=client), reps), cluster_start)
            record("fmu", "Dask LocalCluster", workers,
                   timed(lambda: run_sweep(fmu_spec, "fmu", fmu=fmu, scheduler=client, release=False), reps),
                   fmu_start)
            client.run(release_fmus)
    tmp.cleanup()

    from sweep_goals import goal_lines, machine_scaling, sweep_over_model, write_over_gather

    ceiling = machine_scaling(pkg_spec, repeats=reps)
    print(f"machine scaling ceiling, 1 -> 2 processes without Dask: {ceiling['ratio']:.0%}")

    goal_spec = sweep_spec(max(1, args.goal_cases // (2 * 500)), 500)
    model = sweep_over_model(goal_spec, reps)
    write = write_over_gather(model.pop("result"), model["cases"] // 100_000 or 1, reps)
    print(f"sweep / model: {model['ratio']:.2f}x; Parquet write / in-process join: "
          f"{write['parquet_s'] / write['gather_s']:.2f}x, / raw bytes: {write['parquet_s'] / write['raw_s']:.2f}x")
    streamed = None
    n_streamed = int(args.streamed_cases)
    if n_streamed > 0:
        import shutil

        from sweep_goals import streamed_run

        need = n_streamed * 300  # bytes on disk per case of the streamed parts, measured: 264
        free = shutil.disk_usage(tempfile.gettempdir()).free
        if free < 1.2 * need:
            print(f"streamed run skipped: it needs about {need / 1e9:.0f} GB in {tempfile.gettempdir()}, "
                  f"{free / 1e9:.0f} GB are free")
        else:
            streamed = []
            for n in (n_streamed // 10, n_streamed):  # a tenth, then the whole: memory must not grow with n
                with open_client("local", n_workers=2) as client, tempfile.TemporaryDirectory() as parts:
                    streamed.append(streamed_run(sweep_spec(max(1, n // (2 * 1000)), 1000), client, Path(parts)))
                print(f"streamed: {streamed[-1]['cases']:,} cases in {streamed[-1]['wall_s']:.0f} s, "
                      f"peak memory {streamed[-1]['peak_gb']:.1f} GB")

    load_after = os.getloadavg()[0]
    rate = {(r["path"], r["where"], r["workers"]): r["rate"] for r in rows}
    eff = {p: rate[(p, "Dask LocalCluster", 2)] / (2 * rate[(p, "Dask LocalCluster", 1)]) for p in ("package", "fmu")}
    cpu = {(r["path"], r["where"], r["workers"]): r["total_cpu"] for r in rows}
    cpu_eff = {p: cpu[(p, "Dask LocalCluster", 1)] / cpu[(p, "Dask LocalCluster", 2)] for p in ("package", "fmu")}
    lines = [
        f"Measured {time.strftime('%Y-%m-%d')} by `benchmarks/bench_sweep.py` on {machine_workers()} cores "
        f"({cpu_name()}), Python {platform.python_version()}, numpy {np.__version__}, "
        f"dask {dask.__version__}, fmpy {fmpy.__version__}. Sweep: 2 material pairs x approach speed x t/d "
        f"(40 values); the full 37-column table is gathered. Load average (1 min) before / after: "
        f"{load_before:.2f} / {load_after:.2f}.",
        "",
        "| back end | where | workers | cases | wall s | cases/s | wall µs per case per worker "
        "| CPU µs per case: tasks / all processes | all-process CPU per case / single FMU call "
        "| CPU taken by other processes |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        per_case = r["workers"] / r["rate"] * 1e6
        lines.append(f"| {r['path']} | {r['where']} | {r['workers']} | {r['cases']:,} | {r['elapsed']:.2f} | "
                     f"{r['rate']:,.0f} | {per_case:.2f} | {r['cpu']:.2f} / {r['total_cpu']:.2f} | "
                     f"{r['total_cpu'] / single['e_cpu']:.2f}x | {r['others']:.0%} |")
    lines += [
        "",
        f"- Single FMU call (fmi2SetReal of `v_approach`, `plate.t` + fmi2GetReal of `e`, host loop in one "
        f"process): **{single['e']:.1f} µs** wall, {single['e_cpu']:.1f} µs CPU; reading all 17 outputs as a "
        f"sweep case does: {single['all']:.1f} µs.",
        f"- Scaling efficiency from 1 to 2 workers, rate(2) / (2 rate(1)): package **{eff['package']:.0%}**, "
        f"FMU **{eff['fmu']:.0%}** (the machine has {machine_workers()} cores, which the scheduler, this "
        f"client and the workers share with any other process: last column). In CPU time, which other "
        f"processes do not disturb, CPU per case with 1 worker / with 2 workers: package "
        f"**{cpu_eff['package']:.0%}**, FMU **{cpu_eff['fmu']:.0%}** (100%: a second worker adds no work).",
        "- CPU µs per case, *tasks*: inside the Dask tasks (building the cases, evaluating them); *all "
        "processes*: this client with the LocalCluster's scheduler, the nannies and the workers, so Dask's "
        f"own overhead and gathering the table back are included. Each the least of {args.repeats} runs "
        "(anything else on the machine only adds CPU time); rates from the fastest.",
        "- Start-up, not in the rates: a LocalCluster of 1 / 2 workers took "
        + " / ".join(f"{r['startup']:.1f} s" for r in rows if r["path"] == "package" and r["startup"] is not None)
        + "; loading the FMU into the workers (shipping it, extracting, instantiating) "
        + " / ".join(f"{r['startup']:.2f} s" for r in rows if r["path"] == "fmu" and r["startup"] is not None) + ".",
    ]
    one_worker = next(r for r in rows if r["path"] == "package" and r["workers"] == 1 and r["where"] == "Dask LocalCluster")
    task_cpu, dask_gather = one_worker["cpu"], one_worker["total_cpu"] - one_worker["cpu"]
    lines += ["", "**Goals** (each ratio's two sides measured in this run):", "",
              *goal_lines(model, write, cpu_eff, task_cpu, streamed, dask_gather, ceiling)]
    table = "\n".join(lines)
    print()
    print(table)
    print(f"\n(benchmark took {time.perf_counter() - t_all:.0f} s)")
    if not args.no_write:
        text = DOC.read_text(encoding="utf-8")
        if BEGIN not in text or END not in text:
            raise SystemExit(f"{DOC} has no {BEGIN} ... {END} block to fill")
        text = re.sub(re.escape(BEGIN) + ".*?" + re.escape(END), lambda m: f"{BEGIN}\n{table}\n{END}", text,
                      flags=re.S)
        DOC.write_text(text, encoding="utf-8")
        print(f"wrote {DOC.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
