"""Issue 8's and issue 9's JSBSim evaluations spread over many cores, in arms paired on the same flights.

The evaluation scripts run one flight or case after another in one process. On a many-core machine (the lent
16-core device machine of the fortieth session) this runner flies the flights once, then runs each (flight or
case group) x arm as one job in a pool of worker processes, each pinned to one core. An *arm* is a name and the
extra command-line options of the evaluation script (``benchmarks/eval_jsbsim.py`` or
``benchmarks/eval_jsbsim_diagnose.py``), e.g. ``base:--wind-residual-scale off``. Every job calls the script's
``main`` with its arm's options in its own work folder, which holds hard links of the flown flights, so the arms
see the same flights. A worker runs many jobs and the scripts set module-level switches from their options, so
every arm must name the same options (``base:--x off`` against ``cand:--x on``, never ``cand:--x on`` alone):
:func:`parse_arms` refuses arms that do not.

Each finished job's lines are appended to ``OUT/<arm>.jsonl`` at once (issue 8: ``OUT/<arm>-g<GP seed>.jsonl``),
so a run cut short still leaves paired lines; ``OUT/log.txt`` has one line per job. No job starts after
``--budget`` seconds. Count the files with ``benchmarks/issue8_counts.py`` and ``benchmarks/issue9_counts.py``.

Usage (from the repository root, ``PYTHONPATH=.``; ``JAX_PLATFORMS=cpu`` on a GPU machine)::

    python benchmarks/pool_eval.py issue8 --seeds 4 5 6 --gp-seeds 0 1 \\
        --arm "base:--wind-residual-scale off" --arm "ws:--wind-residual-scale on" --work /tmp/w8 --out OUT8
    python benchmarks/pool_eval.py issue9 --seed 3 --clean-seeds 21 22 23 24 25 \\
        --arm "base:--wind-residual-scale off" --arm "ws:--wind-residual-scale on" --work /tmp/w9 --out OUT9
"""

from __future__ import annotations

import argparse
import contextlib
import io
import multiprocessing as mp
import os
import shlex
import sys
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

#: the 25 roster aircraft in the order of ``benchmarks/records/README.md`` (its arms A then B)
ROSTER = ("c172x pa28 c182 t6 f16 rascal asw20 c684 b737 eternity ka350 dr1 fokker50 "
          "sgs j3cub t37 b747 f4n sgs126 iar80 ultrastick c172p us25e s23 navion").split()
#: issue 9's six effects in two job groups (a job diagnoses one aircraft's group at both sizes)
EFFECT_GROUPS = (("Cm:alpha^2", "Cl:alpha*beta", "Cn:delta_a"), ("CY:scale", "delay:delta_e", "bias:airspeed"))

T0 = time.time()


def parse_arms(specs: list[str]) -> list[tuple[str, list[str]]]:
    """Arms from ``NAME:OPTIONS`` strings (``OPTIONS`` split as a shell would).

    Returns:
        ``[(name, [option tokens])]`` in the order given.

    Raises:
        ValueError: a spec has no ``:``, an empty or repeated name, or the arms do not name the same options
            (the ``--`` tokens): a worker keeps a switch one arm set when it runs the next arm's job.
    """
    arms, names = [], set()
    for spec in specs:
        name, sep, rest = spec.partition(":")
        name = name.strip()
        if not sep or not name:
            raise ValueError(f"arm {spec!r}: expected NAME:OPTIONS, e.g. 'base:--wind-residual-scale off'")
        if name in names:
            raise ValueError(f"arm {name!r} given twice")
        names.add(name)
        arms.append((name, shlex.split(rest)))
    keys = {name: sorted(t.split("=", 1)[0] for t in toks if t.startswith("--")) for name, toks in arms}
    if len({tuple(k) for k in keys.values()}) > 1:
        raise ValueError("every arm must name the same options (a worker keeps the switches an earlier job set): "
                         + "; ".join(f"{n}: {' '.join(k) or '(none)'}" for n, k in keys.items()))
    return arms


def _pin(counter) -> None:
    """Pool initializer: one core per worker (JAX's thread pool sizes itself by the affinity; BLAS gets one thread)."""
    with counter.get_lock():
        i = counter.value
        counter.value += 1
    cpus = sorted(os.sched_getaffinity(0))
    os.sched_setaffinity(0, {cpus[i % len(cpus)]})
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")   # the environment's limit holds only where BLAS loads after it


def _quiet(module: str, args: list[str]):
    """``module.main(args)`` with its output captured; returns (exit status or ``"exc"``, output)."""
    import importlib

    main = importlib.import_module(module).main
    buf = io.StringIO()
    try:
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
            rc = main(args)
    except BaseException:        # a job's failure is logged; the pool goes on
        rc = "exc"
        buf.write(traceback.format_exc())
    return rc, buf.getvalue()


def _link_flights(src: Path, dst: Path, prefix: str | tuple[str, ...] = "") -> None:
    """Hard links of ``src``'s files (starting with ``prefix``, or one of them) in ``dst``, the runs'
    ``results.jsonl`` left out."""
    dst.mkdir(parents=True, exist_ok=True)
    for f in src.iterdir():
        if f.is_file() and f.name.startswith(prefix) and f.name != "results.jsonl" and not (dst / f.name).exists():
            os.link(f, dst / f.name)


# -- issue 8: eval_jsbsim.py, one flight x GP seed x arm per job --------------------------------------------------

def _fly8(job):
    ac, seed, work = job
    t = time.time()
    rc, log = _quiet("benchmarks.eval_jsbsim", ["--aircraft", ac, "--seeds", str(seed), "--turbulence", "light",
                                                "--work", str(work / "FLY"), "--fly-only"])
    return f"fly {ac} s{seed}", rc, time.time() - t, None, log[-1500:]


def _eval8(job):
    ac, seed, gp_seed, arm, opts, work, budget = job
    tag = f"{arm}-g{gp_seed} {ac} s{seed}"
    if time.time() - T0 > budget:
        return tag, "skipped", 0.0, None, ""
    t = time.time()
    stem = f"{ac}-light-s{seed}-ahrs"
    d = work / f"{arm}-g{gp_seed}"
    _link_flights(work / "FLY", d, (stem + "-", stem + "."))
    js = work / "json" / f"{arm}-g{gp_seed}-{stem}.jsonl"
    js.parent.mkdir(parents=True, exist_ok=True)
    js.unlink(missing_ok=True)
    rc, log = _quiet("benchmarks.eval_jsbsim", ["--aircraft", ac, "--seeds", str(seed), "--turbulence", "light",
                                                "--work", str(d), "--gp-seed", str(gp_seed), "--json", str(js),
                                                *opts])
    return tag, rc, time.time() - t, (js.read_text() if js.exists() else None), log[-1500:]


# -- issue 9: eval_jsbsim_diagnose.py, one aircraft x effect group (or its clean flights) x arm per job ------------

def _common9(seed: int) -> list[str]:
    return ["--seeds", str(seed), "--pairs", "--plan", "sweep"]


def _fly9(job):
    ac, seed, clean, work = job
    t = time.time()
    rc, log = _quiet("benchmarks.eval_jsbsim_diagnose",
                     ["--aircraft", ac, *_common9(seed), "--effects", "none", "--clean-seeds", *map(str, clean),
                      "--fly-only", "--out", str(work / "FLY" / ac)])
    return f"fly {ac}", rc, time.time() - t, None, log[-1500:]


def _eval9(job):
    ac, seed, clean, group, arm, opts, work, budget = job
    tag = f"{arm} {ac} {'clean' if group is None else ' '.join(group)}"
    if time.time() - T0 > budget:
        return tag, "skipped", 0.0, None, ""
    t = time.time()
    d = work / f"{arm}-{ac}-{'clean' if group is None else EFFECT_GROUPS.index(group)}"
    _link_flights(work / "FLY" / ac, d)
    sel = ["--effects", "none", "--clean-seeds", *map(str, clean)] if group is None else \
        ["--effects", *group, "--clean-seeds"]
    rc, log = _quiet("benchmarks.eval_jsbsim_diagnose",
                     ["--aircraft", ac, *_common9(seed), *sel, *opts, "--out", str(d)])
    res = d / "results.jsonl"
    return tag, rc, time.time() - t, (res.read_text() if res.exists() else None), log[-1500:]


def _apply(fn_job):
    """``(job, fn(job))``: the pool's unordered results keep their job."""
    fn, job = fn_job
    return job, fn(job)


def _run_pool(procs: int, phases, out: Path, outfile) -> int:
    """Run each phase's jobs in one pool (a phase starts when the last one ends); returns how many jobs failed."""
    out.mkdir(parents=True, exist_ok=True)
    failed = 0
    with open(out / "log.txt", "a") as logf:
        def log(msg):
            logf.write(f"[{time.time() - T0:7.1f}] {msg}\n")
            logf.flush()

        ctx = mp.get_context("fork")
        counter = ctx.Value("i", 0)
        with ctx.Pool(procs, initializer=_pin, initargs=(counter,)) as pool:
            for fn, jobs in phases:
                log(f"{fn.__name__}: {len(jobs)} jobs on {procs} processes")
                for job, (tag, rc, dt, text, tail) in pool.imap_unordered(_apply, [(fn, j) for j in jobs]):
                    if rc == "skipped":
                        log(f"skip {tag}")
                        continue
                    n = len(text.splitlines()) if text else 0
                    log(f"{tag} rc={rc} {dt:.1f} s, {n} lines" + ("" if rc == 0 else "\n" + tail))
                    failed += rc != 0
                    if text:
                        with open(out / outfile(job), "a") as fh:
                            fh.write(text if text.endswith("\n") else text + "\n")
        log("done")
    return failed


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="what", required=True)
    for name in ("issue8", "issue9"):
        p = sub.add_parser(name)
        p.add_argument("--aircraft", nargs="+", default=list(ROSTER))
        p.add_argument("--arm", action="append", required=True, metavar="NAME:OPTIONS",
                       help="an arm: its name and the evaluation script's options (every arm names the same ones)")
        p.add_argument("--work", required=True, help="flights and per-job folders (hard links need one file system)")
        p.add_argument("--out", required=True, help="OUT/<arm>[-g<GP seed>].jsonl and OUT/log.txt")
        p.add_argument("--procs", type=int, default=len(os.sched_getaffinity(0)))
        p.add_argument("--budget", type=float, default=float("inf"), help="no job starts after this many seconds")
        if name == "issue8":
            p.add_argument("--seeds", nargs="+", type=int, required=True)
            p.add_argument("--gp-seeds", nargs="+", type=int, default=[0, 1])
        else:
            p.add_argument("--seed", type=int, required=True)
            p.add_argument("--clean-seeds", nargs="*", type=int, default=[])
            p.add_argument("--clean-only-arms", nargs="*", default=[], metavar="NAME",
                           help="arms run on the clean flights only")
    a = ap.parse_args(argv)
    try:
        arms = parse_arms(a.arm)
    except ValueError as exc:
        ap.error(str(exc))
    unknown = sorted(set(getattr(a, "clean_only_arms", [])) - {n for n, _ in arms})
    if unknown:
        ap.error(f"--clean-only-arms {' '.join(unknown)}: no such --arm")
    # One BLAS thread per worker, set before NumPy loads: the parent imports the harness (and NumPy, whose OpenBLAS
    # sizes its thread pool from every core at import) before the workers fork and pin themselves to one core. A
    # 16-core machine then ran 16 BLAS threads inside each pinned worker and no case finished in nine minutes
    # (forty-fifth session); on a 2-core box a case took 40 s against 7-8 s with one thread. :func:`_pin` also
    # limits BLAS in each worker, for a NumPy loaded before this line.
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    from benchmarks import jsbsim_harness  # noqa: F401  (installs the derived JSBSim models once, before the fork)

    work, out = Path(a.work), Path(a.out)
    if a.what == "issue8":
        fly = [(ac, s, work) for ac in a.aircraft for s in a.seeds]
        ev = [(ac, s, g, n, o, work, a.budget) for ac in a.aircraft for s in a.seeds for g in a.gp_seeds
              for n, o in arms]
        failed = _run_pool(a.procs, [(_fly8, fly), (_eval8, ev)], out, lambda j: f"{j[3]}-g{j[2]}.jsonl")
    else:
        fly = [(ac, a.seed, a.clean_seeds, work) for ac in a.aircraft]
        ev = [(ac, a.seed, a.clean_seeds, grp, n, o, work, a.budget) for n, o in arms
              if n not in a.clean_only_arms for grp in EFFECT_GROUPS for ac in a.aircraft]
        if a.clean_seeds:
            ev += [(ac, a.seed, a.clean_seeds, None, n, o, work, a.budget) for ac in a.aircraft for n, o in arms]
        failed = _run_pool(a.procs, [(_fly9, fly), (_eval9, ev)], out, lambda j: f"{j[4]}.jsonl")
    print(f"{failed} jobs failed; log: {out / 'log.txt'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
