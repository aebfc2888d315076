#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Every field a report writes is documented: runs validate-geometry on eight kinds of run (sampled,
explicit, streaming, impact, bounce, unequal radii, mesh body, mesh bounce; ~20 s together) and
fails naming each key of any report.json, at any depth, that docs/report-json.md does not name --
inside a `code span` or a {brace, list}. Keys that are data (family.adjusted_p's test names)
are not identifiers and are skipped.

  report_fields.py PAGE VALIDATE_GEOMETRY WORKDIR [REPORT.json ...]
With REPORT files given, checks those instead of running (the ctest's power check feeds a page
with a field removed and must fail)."""
import json, re, shutil, subprocess, sys, pathlib

RUNS = [
    ['--mode', 'sampled', '--drops', '20000'],
    ['--asperities', '1000', '--asperity-radius', '6e-5', '--drops', '20000'],
    ['--asperities', '1000', '--asperity-radius', '6e-5', '--drops', '200000', '--spheres', '500', '--statistics', 'streaming'],
    ['--preset', 'fig4', '--asperities', '1000', '--asperity-radius', '6e-5', '--drops', '20000'],
    ['--preset', 'fig6', '--sequences', '50'],
    ['--scene', 'scenes/two-levels.toml', '--asperities', '5000', '--drops', '5000'],
    ['--scene', 'scenes/ellipsoid.toml', '--drops', '2000'],
    ['--scene', 'scenes/ellipsoid-bounce.toml', '--sequences', '20'],
]


def documented(page):
    words = set()
    for span in re.findall(r'`([^`]*)`', page):
        words.update(re.findall(r'[A-Za-z_][A-Za-z0-9_]*', span))
    text = page
    while True:  # brace lists {a, b {c, d}}: innermost first
        inner = re.findall(r'\{([^{}]*)\}', text)
        if not inner:
            return words
        for span in inner:
            words.update(re.findall(r'[A-Za-z_][A-Za-z0-9_]*', span))
        text = re.sub(r'\{[^{}]*\}', ' ', text)


def keys(v, path, out):
    if isinstance(v, dict):
        for k, x in v.items():
            out.setdefault(k, path)
            keys(x, f'{path}.{k}', out)
    elif isinstance(v, list):
        for x in v:
            keys(x, path + '[]', out)


def main():
    page, vg, work = pathlib.Path(sys.argv[1]), sys.argv[2], pathlib.Path(sys.argv[3])
    root = pathlib.Path(__file__).resolve().parents[2]
    reports = [pathlib.Path(p) for p in sys.argv[4:]]
    if not reports:
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir(parents=True)
        for i, args in enumerate(RUNS):
            out = work / str(i)
            rc = subprocess.run([vg, *args, '--no-plots', '--quiet', '--out', str(out)], cwd=root,
                                stdout=subprocess.DEVNULL).returncode
            if rc not in (0, 1):
                sys.exit(f'report_fields: validate-geometry {" ".join(args)} exited {rc}')
            reports.append(out / 'report.json')
    words = documented(page.read_text())
    found = {}
    for r in reports:
        keys(json.loads(r.read_text()), '', found)
    missing = sorted((k, p) for k, p in found.items() if re.fullmatch(r'[A-Za-z_]\w*', k) and k not in words)
    for k, p in missing:
        print(f'report_fields: {p or "(top)"}.{k} is written by a report but not documented in {page.name}')
    print(f'report_fields: {len(found)} distinct keys in {len(reports)} reports, {len(missing)} undocumented')
    return 1 if missing else 0


if __name__ == '__main__':
    sys.exit(main())
