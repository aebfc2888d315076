#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Golden reports: the proof that a restructuring left every result unchanged (issue 38).

Runs validate-geometry on reduced copies of every preset and of every scenes/*.toml (every kind of
run: sphere, unequal radii, mesh body, bounce, mesh bounce; raw and streaming statistics; a run
whose decisive family rejects), and compares each report.json field by field with the stored copy
in reports/. Then runs the error corpus (errors.json): every option with a bad value, and a few
scene-file keys, each with its exit status and its whole message.

Usage (ctest runs the first; tests/golden/README.md):
    golden.py --cli build/release/validate-geometry            # compare
    golden.py --cli build/release/validate-geometry --update   # rewrite the stored copies
    golden.py --cli ... --only fig4 --threads 1                # one case, another thread count
"""
import argparse
import concurrent.futures
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
SRC = HERE.parent.parent

# The normalisations, and the only ones: what must differ between two runs of the same scene.
# 1. Wall-clock time: every key "timings_s" (the object), "seconds", "seconds_*", "*_per_second";
#    among them the plan's stage seconds (plan[].seconds) and the run's "seconds" fields.
# 2. "tool_version": the version that wrote the report (a release would rewrite every file).
# 3. Absolute paths in any string: the output directory -> <out>, the temporary directory the
#    test writes its scene files in -> <tmp>, the source tree (mesh files, scenes) -> <src>.
# "scene_file" and the plan's reasons are compared as they are.
TIMED = re.compile(r"^(timings_s|seconds|seconds_.*|.*_per_second)$")


def normalise(value, paths):
    if isinstance(value, dict):
        return {k: normalise_field(k, v, paths) for k, v in value.items()}
    if isinstance(value, list):
        return [normalise(v, paths) for v in value]
    if isinstance(value, str):
        for path, name in paths:
            value = value.replace(path, name)
    return value


def normalise_field(key, value, paths):
    if key == "tool_version":
        return "<version>"
    if key == "timings_s" and isinstance(value, dict):  # which stages were timed is kept
        return {k: "<time>" for k in value}
    if TIMED.match(key) and isinstance(value, (int, float)) and not isinstance(value, bool):
        return "<time>"  # null (a stage that did not run) stays null
    return normalise(value, paths)


# Reduced runs: small N, few drops, no figures. Every preset (--preset) and every scene file
# (--scene): the two paths read the same text but echo it differently (scene_file).
SMALL = ["--asperities", "2000", "--drops", "4000"]
RUNS = {
    "preset-fig3": ["--preset", "fig3", *SMALL],
    "preset-fig3-fixed": ["--preset", "fig3-fixed", *SMALL, "--spheres", "20"],
    "preset-fig4": ["--preset", "fig4", *SMALL],
    "preset-fig5": ["--preset", "fig5", *SMALL],
    "preset-fig6": ["--preset", "fig6", "--asperities", "2000", "--sequences", "40"],
    "scene-fig3": ["--scene", "scenes/fig3.toml", *SMALL],
    "scene-fig3-fixed": ["--scene", "scenes/fig3-fixed.toml", *SMALL, "--spheres", "20"],
    "scene-fig4": ["--scene", "scenes/fig4.toml", *SMALL],
    "scene-fig5": ["--scene", "scenes/fig5.toml", *SMALL],
    "scene-fig6": ["--scene", "scenes/fig6.toml", "--asperities", "2000", "--sequences", "40"],
    "scene-example": ["--scene", "scenes/example.toml", "--asperities", "2000", "--drops", "4000"],
    "scene-two-levels": ["--scene", "scenes/two-levels.toml", "--asperities", "2000", "--drops", "4000"],
    "scene-ellipsoid": ["--scene", "scenes/ellipsoid.toml", "--asperities", "2000", "--drops", "400", "--spheres", "2"],
    "scene-ellipsoid-bounce": ["--scene", "scenes/ellipsoid-bounce.toml", "--asperities", "2000", "--sequences", "8",
                               "--spheres", "2"],
    "scene-ellipsoid-bounce-stronge": ["--scene", "scenes/ellipsoid-bounce-stronge.toml", "--asperities", "2000",
                                       "--sequences", "8", "--spheres", "2"],
    # The other paths of the verdicts: the sampled design, streaming statistics, the tangential laws.
    "fig4-sampled": ["--preset", "fig4", "--mode", "sampled", *SMALL],
    "fig3-streaming": ["--preset", "fig3", "--statistics", "streaming", "--bins-log2", "10", *SMALL],
    "fig4-kinematic-0.9": ["--preset", "fig4", "--tangential", "kinematic:eps_t=0.9", *SMALL],
    "fig4-coulomb": ["--preset", "fig4", "--tangential", "coulomb:mu=0.05,restitution=newton", *SMALL],
    # N = 5: Eq. 18 (the continuum law) is plainly wrong, and the decisive family rejects (exit 1).
    "reject-n5": ["--preset", "fig3", "--mode", "sampled", "--asperities", "5", "--drops", "20000"],
    "reject-n5-explicit": ["--preset", "fig3", "--asperities", "5", "--drops", "20000", "--spheres", "20"],
}

# Scene files the error corpus reads: fig3's text with one key changed.
FIG3 = (SRC / "scenes/fig3.toml").read_text()
FIG6 = (SRC / "scenes/fig6.toml").read_text()
SCENES = {
    "drops-1": FIG3.replace("drops = 1000000", "drops = 1"),
    "drops-0": FIG3.replace("drops = 1000000", "drops = 0"),
    "drops-text": FIG3.replace("drops = 1000000", 'drops = "many"'),
    "alpha-2": FIG3.replace("alpha = 0.01", "alpha = 2.0"),
    "count-0": FIG3.replace("count = 100000", "count = 0"),
    "seed-neg": FIG3.replace("seed = 1", "seed = -1"),
    "mode-x": FIG3.replace('mode = "explicit"', 'mode = "x"'),
    "mode-fixed": FIG3.replace('mode = "explicit"', 'mode = "fixed"'),
    "backend-x": FIG3.replace('backend = "auto"', 'backend = "x"'),
    "eps_t-2": FIG3.replace("eps_t = 1.0", "eps_t = 2.0"),
    "unknown-key": FIG3.replace("seed = 1", "seed = 1\nseeds = 2"),
    # drops given in the file of a bounce run: refused as --drops is (accepted at 3dfd20f); small, as it may run
    "fig6-drops": FIG6.replace("count = 1000000", "count = 2000").replace("sequences = 100000", "sequences = 20")
                      .replace("seed = 1", "drops = 1000000\nseed = 1"),
}

# Every option with a bad value (and a few rules that depend on the kind of run).
ERRORS = [
    ["--preset", "fig7"],
    ["--scene", "{tmp}/absent.toml"],
    ["--preset", "fig3", "--scene", "{src}/scenes/fig3.toml"],
    ["--asperities", "0"], ["--asperities", "-3"], ["--asperities", "1.5"], ["--asperities", "1e20"],
    ["--radius", "0"], ["--radius", "x"], ["--radius", "inf"],
    ["--asperity-radius", "-1"], ["--asperity-radius", "1"],
    ["--drops", "-5"], ["--drops", "0"], ["--drops", "1"], ["--drops", "x"], ["--drops", "1e30"],
    ["--mode", "x"], ["--mode", "fresh"], ["--mode", "sampled", "--spheres", "10"],
    ["--spheres", "0"], ["--spheres", "x"],
    ["--seed", "-1"], ["--seed", "x"], ["--seed", "1e20"],
    ["--backend", "x"], ["--mode", "sampled", "--backend", "grid"],
    ["--threads", "-1"], ["--threads", "x"], ["--threads", "100000"],
    ["--kernel", "x"],
    ["--statistics", "x"],
    ["--bins-log2", "9"], ["--bins-log2", "25"], ["--statistics", "streaming", "--bins-log2", "25"],
    ["--checkpoint-every", "-1"], ["--checkpoint-every", "x"],
    ["--resume", "{tmp}/absent"], ["--resume", "{tmp}/absent", "--drops", "10"],
    ["--alpha", "0"], ["--alpha", "1"], ["--alpha", "x"],
    ["--out", ""],
    ["--speed", "0"], ["--speed", "-1"], ["--speed", "x"],
    ["--omega-x", "x"], ["--omega-y", "nan"], ["--omega-x", "1"],
    ["--variant", "paper"], ["--preset", "fig6", "--variant", "x"], ["--preset", "fig6", "--variant", "paper,paper"],
    ["--sequences", "10"], ["--preset", "fig6", "--sequences", "0"],
    ["--tangential", "x"], ["--preset", "fig4", "--tangential", "x"],
    ["--preset", "fig4", "--tangential", "kinematic:eps_t=2"], ["--preset", "fig4", "--tangential", "coulomb:mu=0.3"],
    ["--preset", "fig4", "--tangential", "coulomb:mu=-1,restitution=newton"],
    ["--preset", "fig4", "--tangential", "walton:mu=0.3"],
    ["--plot-format", "x"], ["--plot-format", "png@0"],
    ["--preset", "fig6", "--drops", "1000"], ["--preset", "fig6", "--alpha", "0.05"],
    ["--preset", "fig6", "--mode", "sampled"], ["--preset", "fig6", "--backend", "grid"],
    ["--scene", "{src}/scenes/two-levels.toml", "--speed", "1"], ["--scene", "{src}/scenes/two-levels.toml", "--mode", "explicit"],
    ["--scene", "{src}/scenes/ellipsoid.toml", "--radius", "1e-3"], ["--scene", "{src}/scenes/ellipsoid.toml", "--mode", "sampled"],
    ["--no-such-option"],
    ["--out", "--no-plots"],
] + [["--scene", "{scene:" + name + "}"] for name in SCENES]


def run(cli, args, out, tmp, threads):
    args = [a.replace("{tmp}", str(tmp)).replace("{src}", str(SRC)) for a in args]
    args = [str(tmp / (a[7:-1] + ".toml")) if a.startswith("{scene:") else a for a in args]
    command = [cli, *args, "--quiet", "--no-plots"]
    if out is not None:
        command += ["--out", str(out), "--threads", str(threads)]
    # An error case runs in the temporary directory: one that is accepted writes nothing into the tree.
    return subprocess.run(command, cwd=SRC if out else tmp, capture_output=True, text=True, timeout=600)


def differences(expected, got, where=""):
    """Field-by-field differences, each as 'path: expected X, got Y'."""
    if isinstance(expected, dict) and isinstance(got, dict):
        out = []
        for k in expected.keys() | got.keys():
            if k not in got:
                out.append(f"{where}.{k}: missing (expected {json.dumps(expected[k])[:80]})")
            elif k not in expected:
                out.append(f"{where}.{k}: new field ({json.dumps(got[k])[:80]})")
            else:
                out += differences(expected[k], got[k], f"{where}.{k}")
        return out
    if isinstance(expected, list) and isinstance(got, list):
        out = [f"{where}: {len(expected)} entries expected, {len(got)} got"] if len(expected) != len(got) else []
        for i, (e, g) in enumerate(zip(expected, got)):
            out += differences(e, g, f"{where}[{i}]")
        return out
    if expected != got or type(expected) is not type(got):
        return [f"{where}: expected {json.dumps(expected)[:200]}, got {json.dumps(got)[:200]}"]
    return []


def golden_run(cli, name, args, tmp, threads):
    out = tmp / ("out-" + name)
    r = run(cli, args, out, tmp, threads)
    paths = [(str(out), "<out>"), (str(tmp), "<tmp>"), (str(SRC), "<src>")]
    result = {"args": args, "status": r.returncode}
    if r.returncode in (0, 1):
        result["report"] = normalise(json.loads((out / "report.json").read_text()), paths)
        if threads != 1:  # --threads N: the stored copies ran with 1; the scene echoes the option
            text = result["report"].get("scene_file", "")
            result["report"]["scene_file"] = text.replace(f"\nthreads = {threads}\n", "\nthreads = 1\n")
    else:
        result["stderr"] = normalise(r.stderr, paths)
    return name, result


def error_case(cli, args, tmp):
    r = run(cli, args, None, tmp, None)
    paths = [(str(tmp), "<tmp>"), (str(SRC), "<src>")]
    return {"args": args, "status": r.returncode, "stderr": normalise(r.stderr, paths)}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cli", required=True, help="the validate-geometry to test")
    p.add_argument("--update", action="store_true", help="rewrite the stored copies instead of comparing")
    p.add_argument("--only", help="run only the cases whose name contains this (no error corpus unless 'errors')")
    p.add_argument("--threads", type=int, default=1,
                   help="threads per run; the stored copies ran with 1, and reports are the same bits for any thread "
                        "count (the scene_file's 'threads = N' line is read as 1: the one difference allowed)")
    p.add_argument("--jobs", type=int, default=2, help="runs at once")
    a = p.parse_args()
    cli = str(Path(a.cli).resolve())
    start = time.monotonic()
    failures = []
    with tempfile.TemporaryDirectory(prefix="asperity-golden-") as t:
        tmp = Path(t).resolve()
        for name, text in SCENES.items():
            (tmp / (name + ".toml")).write_text(text)
        runs = {n: args for n, args in RUNS.items() if not a.only or a.only in n}
        with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
            done = list(pool.map(lambda kv: golden_run(cli, kv[0], kv[1], tmp, a.threads), runs.items()))
        for name, result in done:
            stored = HERE / "reports" / (name + ".json")
            if a.update:
                stored.write_text(json.dumps(result, indent=1, sort_keys=True) + "\n")
                continue
            if not stored.exists():
                failures.append(f"{name}: no stored report ({stored}); run with --update")
                continue
            failures += [f"{name}{d}" for d in differences(json.loads(stored.read_text()), result)]
        if not a.only or a.only in "errors":
            with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
                corpus = list(pool.map(lambda args: error_case(cli, args, tmp), ERRORS))
            stored = HERE / "errors.json"
            if a.update:
                stored.write_text(json.dumps(corpus, indent=1) + "\n")
            else:
                expected = {json.dumps(c["args"]): c for c in json.loads(stored.read_text())}
                for c in corpus:
                    e = expected.pop(json.dumps(c["args"]), None)
                    if e is None:
                        failures.append(f"errors {c['args']}: not in errors.json; run with --update")
                    elif e != c:
                        failures.append(f"errors {c['args']}: expected status {e['status']}, {e['stderr']!r}; "
                                        f"got status {c['status']}, {c['stderr']!r}")
                failures += [f"errors {args}: in errors.json but no longer run" for args in expected]
    for f in failures:
        print("FAIL", f)
    print(f"golden: {len(runs)} runs, {'no' if a.only and a.only not in 'errors' else len(ERRORS)} error cases, "
          f"{len(failures)} differences, {time.monotonic() - start:.1f} s" + (" (updated)" if a.update else ""))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
