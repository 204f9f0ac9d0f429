"""Hostile score files: time and peak memory until a one-line error (issue 16 item 6).

Each case runs in a fresh subprocess with a wall-clock limit, so a reader
that hangs or exhausts memory is reported as such instead of stopping the
benchmark.  Prints one line per case: outcome, seconds, peak resident MB.

    .venv/bin/python benchmarks/bench_score_guards.py [--timeout 30]

Wall-clock figures on a shared machine are noisy lower bounds.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = r"""
import resource, sys, time
from capture2notation.errors import C2NError
from capture2notation.notation import read
t = time.perf_counter()
try:
    s = read(sys.argv[1])
    out = f"read {len(s.symbols)} symbols"
except C2NError as exc:
    out = "error: " + str(exc).split(": ", 1)[-1][:70]
except Exception as exc:  # what the guards exist to prevent
    out = f"CRASH {type(exc).__name__}: {str(exc)[:60]}"
print(out, "|", round(time.perf_counter() - t, 3), "|", resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024)
"""


def _cases(tmp: Path) -> dict[str, Path]:
    cases = {}

    def put(name, text):
        p = tmp / name
        p.write_text(text, encoding="utf-8")
        cases[name] = p

    put("huge_exponent_tempo.lab", "tempo: 1e100000000\n0 1 head forward high\n")
    put("tiny_tempo.lab", "tempo: 1/1000000\n0 1 head forward high\n")
    put("start_1e9.lab", "1000000000 1 head forward high\n")
    put("deep.json", "[" * 200_000 + "]" * 200_000)
    put("huge_int.json", '{"tempo": ' + "9" * 10_000 + "}")
    lines = ["tempo: 60"] + [f"{i} 1 right_arm forward high" for i in range(330_000)]
    put("ten_mb.lab", "\n".join(lines) + "\n")
    sym = {"start": "0", "duration": "1", "part": "head", "direction": "forward", "level": "high"}
    syms = [dict(sym, start=str(i)) for i in range(120_000)]
    put("ten_mb.json", json.dumps({"symbols": syms}))
    return cases


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--timeout", type=float, default=30.0, help="seconds per case")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        for name, path in _cases(Path(d)).items():
            size = path.stat().st_size / 1e6
            try:
                r = subprocess.run(
                    [sys.executable, "-c", CHILD, str(path)], capture_output=True, text=True, timeout=args.timeout
                )
                line = r.stdout.strip() or ("CRASH " + r.stderr.strip().splitlines()[-1][:80])
            except subprocess.TimeoutExpired:
                line = f"HANG (killed after {args.timeout:g} s)"
            print(f"{name:<26} {size:7.2f} MB  {line}")


if __name__ == "__main__":
    main()
