"""The actuator (the paper's block under a preload, an electrode on its top) swept in voltage:
the contact force on the foundation, and the slip and separation, against the voltage. A
negative voltage lifts the block off the foundation against its preload; a positive one presses
it harder, and the points near the electrode's ends begin to slip.

    python actuator_sweep.py [--n 32] [--points 17] [--vmin -0.1] [--vmax 0.3] [--out figures]
"""

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files, no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import piezocontact as pc  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=32, help="cells along the block's height")
    parser.add_argument("--points", type=int, default=17, help="voltages in the sweep")
    parser.add_argument("--vmin", type=float, default=-0.1, help="smallest voltage (scene units, GV)")
    parser.add_argument("--vmax", type=float, default=0.3, help="largest voltage")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("figures"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    scene = pc.Scene.load("actuator", {"mesh.n": args.n})
    voltages = np.linspace(args.vmin, args.vmax, args.points)
    force, tangential, slip, separated = [], [], [], []
    print(f"{'V':>8} {'normal force':>13} {'tangential':>11} {'slip':>5} {'sep.':>5}")
    for v in voltages:
        scene.set("electrode.v", v)
        c = pc.run(scene).report["contact"]
        force.append(c["normal_force"])
        tangential.append(c["tangential_force"])
        slip.append(c["n_slip"])
        separated.append(c["n_separated"])
        print(f"{v:8.3f} {force[-1]:13.6f} {tangential[-1]:11.6f} {slip[-1]:5d} {separated[-1]:5d}")

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(6, 5.5), sharex=True)
    top.plot(voltages, force, "o-", label="normal")
    top.plot(voltages, tangential, "s-", label="tangential")
    top.set(ylabel="contact force", title="Actuator: contact force against voltage")
    top.legend()
    bottom.step(voltages, slip, where="mid", label="slip")
    bottom.step(voltages, separated, where="mid", label="separated")
    bottom.set(xlabel="electrode voltage V", ylabel="contact points")
    bottom.legend()
    fig.tight_layout()
    fig.savefig(args.out / "actuator-sweep.png", dpi=120)
    print(f"figure written to {args.out}/actuator-sweep.png")


if __name__ == "__main__":
    main()
