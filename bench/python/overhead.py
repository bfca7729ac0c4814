"""The overhead of the Python package against the program, side by side in one session: the
same scene solved and written by `piezocontact run` and by `piezocontact.run` + `write`,
alternately, the medians and their ratio.

    python bench/python/overhead.py [--n 256] [--repeats 5] [--bin target/release/piezocontact]

Three times per repeat: the program's whole process (start, solve, outputs); the Python
package's whole process (interpreter start, import, scene, run, write: `python -c ...`); and,
inside one interpreter, `run()` + `write()` alone. Also each run's own `timings_s.total` (the
solve inside the library), which the two should share.
"""

import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import piezocontact as pc

REPO = pathlib.Path(__file__).resolve().parents[2]


def wall(args):
    t = time.perf_counter()
    subprocess.run(args, check=True, capture_output=True)
    return time.perf_counter() - t


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=256)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--bin", type=pathlib.Path, default=REPO / "target" / "release" / "piezocontact")
    args = parser.parse_args()
    out = pathlib.Path(tempfile.mkdtemp())
    script = (
        "import piezocontact as pc;"
        f"pc.run(pc.Scene.load('paper', {{'mesh.n': {args.n}}})).write({str(out / 'py-process')!r})"
    )
    scene = pc.Scene.load("paper", {"mesh.n": args.n})
    times = {"program": [], "python process": [], "run()+write()": [], "run()": []}
    solve = {"program": [], "python": []}
    for _ in range(args.repeats):
        times["program"].append(wall([str(args.bin), "run", "paper", "--set", f"mesh.n={args.n}", "--out", str(out / "cli")]))
        solve["program"].append(json.loads((out / "cli" / "run.json").read_text())["timings_s"]["total"])
        times["python process"].append(wall([sys.executable, "-c", script]))
        t = time.perf_counter()
        result = pc.run(scene)
        times["run()"].append(time.perf_counter() - t)
        result.write(out / "py")
        times["run()+write()"].append(time.perf_counter() - t)
        solve["python"].append(result.report["timings_s"]["total"])
        del result
    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"paper, mesh.n = {args.n}, {args.repeats} repeats, medians (s):")
    for k, v in med.items():
        print(f"  {k:16} {v:8.3f}   ({', '.join(f'{x:.3f}' for x in times[k])})")
    print(f"  library solve: program {statistics.median(solve['program']):.3f}, python {statistics.median(solve['python']):.3f}")
    # what run() adds to the library's own solve: the thread, the progress channel, the result
    added = [w - s for w, s in zip(times["run()"], solve["python"])]
    print(f"  run() beyond its solve: {statistics.median(added) * 1e3:.1f} ms ({statistics.median(added) / statistics.median(solve['python']):.1%})")
    print(f"ratio python process / program process: {med['python process'] / med['program']:.3f}")
    print(f"ratio run()+write() / program process:   {med['run()+write()'] / med['program']:.3f}")


if __name__ == "__main__":
    main()
