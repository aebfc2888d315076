# SPDX-License-Identifier: GPL-3.0-or-later
"""Python never aborts (issue 24 item 6): every bad call is a Python exception naming the parameter.

Each call runs in a child interpreter: an abort (std::bad_alloc escaping, std::terminate, SIGKILL
by the OOM killer) is then a failed test -- the child's signal -- instead of the end of pytest.
The oversize runs are refused by the up-front memory estimate before anything is allocated, so
each child takes well under a second.
"""
import json
import os
import subprocess
import sys
import textwrap

import pytest

import asperity

# (call, exception type, a text the message must contain: the parameter or key)
CASES = [
    # oversize: the CLI's estimate ("needs about N GB"), before any allocation
    ("asperity.run({'asperities': {'count': 2**32 - 1}, 'outputs': {'plots': False}})", "MemoryError", "asperities.count"),
    ("asperity.run({'asperities': {'count': 10**9}, 'outputs': {'plots': False}})", "MemoryError", "GB of memory"),
    ("asperity.run(MESH_SCENE)", "MemoryError", "faces"),
    ("asperity.run({'experiment': {'kind': 'contact'}, 'ensemble': {'drops': 2**40, 'statistics': 'streaming'}, "
     "'outputs': {'plots': False}}, arrays=True)", "MemoryError", "GB of memory"),
    ("asperity.make_rough_sphere(3 * 10**9)", "MemoryError", "asperities"),
    ("asperity.cor_table(drops=10**9)", "MemoryError", "drops"),
    ("asperity.make_rough_sphere(10**10)", "ValueError", "asperities"),
    ("asperity.run({'asperities': {'count': 10**30}})", "ValueError", "asperities.count"),
    # wrong types, each public parameter
    ("asperity.run(3)", "TypeError", "scene"),
    ("asperity.run('fig4', progress=5)", "TypeError", "progress"),
    ("asperity.run('fig4', arrays='yes')", "TypeError", "arrays"),
    ("asperity.run('fig4', max_array_drops='x')", "TypeError", "max_array_drops"),
    ("asperity.run('fig4', bogus=1)", "TypeError", "bogus"),
    ("asperity.run({'asperities': {'count': 'many'}})", "ValueError", "asperities.count"),
    ("asperity.scene_toml(None)", "TypeError", "scene"),
    ("asperity.preset_text(5)", "TypeError", "name"),
    ("asperity.make_rough_sphere('abc')", "TypeError", "asperities"),
    ("asperity.make_rough_sphere(100, radius='x')", "TypeError", "radius"),
    ("asperity.make_rough_sphere(100, asperity_radius=[1])", "TypeError", "asperity_radius"),
    ("asperity.make_rough_sphere(100, seed=1.5)", "TypeError", "seed"),
    ("asperity.make_rough_sphere(100, sphere_id='0')", "TypeError", "sphere_id"),
    ("asperity.make_rough_sphere(100).query(3)", "TypeError", "backend"),
    ("asperity.make_rough_sphere(100).query().lowest('d')", "TypeError", "d"),
    ("asperity.make_rough_sphere(100).query().contact('q')", "TypeError", "q"),
    ("asperity.body_down({'w': 1})", "TypeError", "q"),
    ("asperity.pade14('x')", "TypeError", "beta"),
    ("asperity.pade14()('x')", "TypeError", "v"),
    ("asperity.constant('x')", "TypeError", "e"),
    ("asperity.solve_impact('m', 1.0, [0, 0, -1], [0, 0, 0], [0, 0, -1])", "TypeError", "mass"),
    ("asperity.solve_impact(1.0, 'J', [0, 0, -1], [0, 0, 0], [0, 0, -1])", "TypeError", "inertia"),
    ("asperity.solve_impact(1.0, 1.0, 'V', [0, 0, 0], [0, 0, -1])", "TypeError", "V"),
    ("asperity.solve_impact(1.0, 1.0, [0, 0, -1], None, [0, 0, -1])", "TypeError", "Omega"),
    ("asperity.solve_impact(1.0, 1.0, [0, 0, -1], [0, 0, 0], object())", "TypeError", "r"),
    ("asperity.solve_impact(1.0, 1.0, [0, 0, -1], [0, 0, 0], [0, 0, -1], n='up')", "TypeError", "n"),
    ("asperity.solve_impact(1.0, 1.0, [0, 0, -1], [0, 0, 0], [0, 0, -1], eps_n='x')", "TypeError", "eps_n"),
    ("asperity.solve_impact(1.0, 1.0, [0, 0, -1], [0, 0, 0], [0, 0, -1], eps_t='x')", "TypeError", "eps_t"),
    ("asperity.eq14_rxy('n', 1.0)", "TypeError", "asperities"),
    ("asperity.exact_sphere_rx(100, 'R')", "TypeError", "radius"),
    ("asperity.exact_sphere_rx(100, 1.0).pdf('x')", "TypeError", "x"),
    ("asperity.eq28_corrected(core_contacts='yes')", "TypeError", "core_contacts"),
    ("asperity.eq33_printed(omega_x='fast')", "TypeError", "omega_x"),
    ("asperity.cor_table(speeds='x')", "TypeError", "speeds"),
    ("asperity.cor_table(spins=['a'])", "TypeError", "spins"),
    ("asperity.cor_table(drops=2.5)", "TypeError", "drops"),
    ("asperity.cor_table(probabilities='many')", "TypeError", "probabilities"),
    ("asperity.cor_table(omega_bands=1.5)", "TypeError", "omega_bands"),
    ("asperity.cor_table(progress=3)", "TypeError", "progress"),
    # negative and NaN values
    ("asperity.make_rough_sphere(-5)", "ValueError", "asperities"),
    ("asperity.make_rough_sphere(100, radius=float('nan'))", "ValueError", "radius"),
    ("asperity.make_rough_sphere(100, radius=-1.0)", "ValueError", "radius"),
    ("asperity.make_rough_sphere(100, seed=2**70)", "ValueError", "seed"),
    # the Python parameter's name, not the CLI flag's (asperity-radius)
    ("asperity.make_rough_sphere(100, asperity_radius=-1.0)", "ValueError", "asperity_radius"),
    ("asperity.make_rough_sphere(100, asperity_radius=1e-20)", "ValueError", "asperity_radius"),
    ("asperity.core_contact_probability(10, 1e-3, -1.0)", "ValueError", "asperity_radius"),
    ("asperity.cor_table(drops=100, speeds=[1.0], probabilities=3, path='t.txt')", "ValueError", ".csv"),
    ("asperity.cor_table(path=5)", "TypeError", "path"),
    ("asperity.read_cor_table('t.txt')", "ValueError", ".csv"),
    ("asperity.pade14(float('nan'))", "ValueError", "beta"),
    ("asperity.pade14()(-1.0)", "ValueError", "v"),
    ("asperity.constant(-0.5)", "ValueError", "e"),
    ("asperity.eq14_rxy(-1, 1.0)", "ValueError", "asperities"),
    ("asperity.eq14_rxy(10, float('nan'))", "ValueError", "radius"),
    ("asperity.eq28_corrected(speed=float('nan'))", "ValueError", "speed"),
    ("asperity.eq28_corrected(speed=-1.0)", "ValueError", "speed"),
    ("asperity.solve_impact(float('nan'), 1.0, [0, 0, -1], [0, 0, 0], [0, 0, -1])", "ValueError", "mass"),
    ("asperity.solve_impact(1.0, -1.0, [0, 0, -1], [0, 0, 0], [0, 0, -1])", "ValueError", "inertia"),
    ("asperity.solve_impact(1.0, 1.0, [0, 0, float('nan')], [0, 0, 0], [0, 0, -1])", "ValueError", "V"),
    ("asperity.cor_table(drops=-3)", "ValueError", "drops"),
    ("asperity.cor_table(probabilities=-3)", "ValueError", "probabilities"),
    ("asperity.run({'ensemble': {'drops': -1}})", "ValueError", "drops"),
    ("asperity.run({'asperities': {'radius': {'distribution': 'fixed', 'value': float('nan')}}})", "ValueError", "radius"),
    # issue 33 item 1: recursive and very deep scene dicts are refused before the conversion
    # recurses (a segfault before), at the scene reader's nesting limit of 16
    ("asperity.run((lambda d: (d.__setitem__('x', d), d)[1])({'format': 1}))", "ValueError", "contains itself"),
    ("asperity.scene_toml({'a': (lambda l: (l.append(l), l)[1])([])})", "ValueError", "a[0] contains itself"),
    ("asperity.scene_toml({'a': __import__('functools').reduce(lambda a, _: [a], range(10**5), 0)})", "ValueError",
     "nested more than 16 deep"),
    ("asperity.scene_toml(__import__('functools').reduce(lambda a, _: {'k': a}, range(10**5), 0))", "ValueError",
     "nested more than 16 deep"),
    # issue 33 item 8: a lone surrogate names its parameter or key; a bytes __fspath__ is a path
    ("asperity.preset_text('\\ud800')", "ValueError", "name"),
    ("asperity.scene_toml('\\ud800')", "ValueError", "scene"),
    ("asperity.scene_toml({'name': '\\ud800'})", "ValueError", "scene dict: name"),
    ("asperity.scene_toml({'\\ud800': 1})", "ValueError", "scene dict: a key"),
    ("asperity.run('fig4', out='\\ud800')", "ValueError", "out"),
]

# One child interpreter runs every call in turn and prints one JSON line per call: an abort stops
# it, and the calls without a line (the first of them killed it) fail.
CHILD = textwrap.dedent("""
    import json, sys
    import asperity
    MESH_SCENE = json.loads(sys.argv[2])
    for call in json.loads(sys.argv[1]):
        try:
            eval(call)
            out = ["none", ""]
        except BaseException as e:
            out = [type(e).__name__, str(e)]
        print(json.dumps([call] + out), flush=True)
""")


def mesh_scene(tmp):
    """A mesh body whose file states 2e9 faces: refused from its header, before read_mesh."""
    off = tmp / "huge.off"
    off.write_text("OFF\n1000000000 2000000000 0\n0 0 0\n")
    return {"body": {"kind": "mesh", "mesh": str(off)}, "ensemble": {"mode": "explicit", "spheres": 1, "drops": 100},
            "experiment": {"kind": "impact", "V": [0.0, 0.0, -1.3], "Omega": [0.2, 0.0, 0.0]}, "outputs": {"plots": False, "dir": str(tmp / "out")}}


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("errors")
    # The package this pytest imports, whatever the working directory.
    package = os.path.dirname(os.path.dirname(os.path.abspath(asperity.__file__)))
    env = dict(os.environ, OMP_NUM_THREADS="2", PYTHONPATH=package)
    r = subprocess.run([sys.executable, "-c", CHILD, json.dumps([c[0] for c in CASES]), json.dumps(mesh_scene(tmp))],
                       capture_output=True, text=True, timeout=300, env=env, cwd=tmp)
    seen = {}
    for line in r.stdout.splitlines():
        call, kind, message = json.loads(line)
        seen[call] = (kind, message)
    return seen, r, tmp


@pytest.mark.parametrize("call,kind,named", CASES, ids=[c[0][:70] for c in CASES])
def test_a_bad_call_is_an_exception_naming_the_parameter(call, kind, named, outcomes):
    seen, r, tmp = outcomes
    assert call in seen, f"{call}: the interpreter died (status {r.returncode}) here or before:\n{r.stderr[-2000:]}"
    got, message = seen[call]
    assert got == kind, f"{call}: {got}: {message}"
    assert named in message, f"{call}: the message does not name {named!r}: {message}"
    assert not (tmp / "out").exists(), f"{call}: a refused run created its output directory"


# Issue 33: the scene-dict entry points (asperity.scene_toml, the conversion asperity.run uses)
# against random Python objects -- nesting up to 24 deep, cycles, lone surrogates, numpy scalars,
# integers beyond 64 bits, NaN, bytes, None -- in a child interpreter (seeded, 3000 inputs): every
# input is either converted or refused with TypeError/ValueError; anything else (a crash, another
# exception type) fails. A bounded, reproducible stand-in for fuzzing the Python entry points.
FUZZ_CHILD = textwrap.dedent("""
    import json, random, sys
    import numpy as np
    import asperity
    rng = random.Random(33)
    KEYS = ["format", "name", "body", "asperities", "count", "ensemble", "seed", "drops", "experiment",
            "kind", "outputs", "plots", "\\ud800", "x" * 40, "", "a.b"]
    def scalar():
        return rng.choice([0, 1, -1, 2**63, 2**64 - 1, 2**64, 10**30, 1.5, float("nan"), float("inf"), True,
                           None, "fig4", "\\ud800", "\\x1b[2J", b"bytes", np.uint64(2**64 - 1), np.int32(-5),
                           np.float64(2.5), np.bool_(True), object()])
    def value(depth):
        r = rng.random()
        if depth > 24 or r < 0.5:
            return scalar()
        if r < 0.75:
            return {rng.choice(KEYS): value(depth + 1) for _ in range(rng.randint(0, 3))}
        return [value(depth + 1) for _ in range(rng.randint(0, 3))]
    counts = {}
    for i in range(3000):
        v = value(0)
        if not isinstance(v, dict):
            v = {rng.choice(KEYS): v}
        if rng.random() < 0.05:
            v["self"] = v
        try:
            asperity.scene_toml(v)
            kind = "ok"
        except (TypeError, ValueError) as e:
            kind = type(e).__name__
        except BaseException as e:
            print(json.dumps(["unexpected", i, type(e).__name__, str(e)[:200]]), flush=True)
            sys.exit(3)
        counts[kind] = counts.get(kind, 0) + 1
    print(json.dumps(counts), flush=True)
""")


def test_random_scene_dicts_convert_or_raise_type_or_value_error(tmp_path):
    package = os.path.dirname(os.path.dirname(os.path.abspath(asperity.__file__)))
    env = dict(os.environ, OMP_NUM_THREADS="2", PYTHONPATH=package)
    r = subprocess.run([sys.executable, "-c", FUZZ_CHILD], capture_output=True, text=True, timeout=300, env=env, cwd=tmp_path)
    assert r.returncode == 0, f"status {r.returncode}: {r.stdout[-2000:]} {r.stderr[-2000:]}"
    counts = json.loads(r.stdout.strip().splitlines()[-1])
    assert sum(counts.values()) == 3000
    assert counts.get("ok", 0) > 0 and counts.get("ValueError", 0) > 0, counts  # both outcomes reached
