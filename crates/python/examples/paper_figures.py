"""The paper's Figures 2-6 (Bouallala, Essoufi & Zafrar, section 4.2) from `piezocontact.run`:
the deformed block (Fig. 2), the multipliers for F = 0.6 under p = -2 (Fig. 3), the contour
plot of the electric potential (Fig. 4), and the multipliers under the loads -4 and -6
(Figs. 5 and 6).

    python paper_figures.py [--n 64] [--out figures]
"""

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files, no window
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402

import piezocontact as pc  # noqa: E402


def multipliers(result, title, path):
    """lambda_n and lambda_t along the contact boundary, by x."""
    c = result.contact
    order = c.x[:, 0].argsort()
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(c.x[order, 0], c.lambda_n[order], "o-", ms=3, label=r"$\lambda_N$")
    ax.plot(c.x[order, 0], c.lambda_t[order, 0], "s-", ms=3, label=r"$\lambda_T$")
    ax.set(xlabel="x", ylabel="multiplier", title=title)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=64, help="cells along the block's height")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("figures"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    scene = pc.Scene.load("paper", {"mesh.n": args.n})
    result = pc.run(scene, progress=True)
    triangles = mtri.Triangulation(result.points[:, 0], result.points[:, 1], result.cells)

    # Figure 2: the deformed configuration (displacements magnified to be seen)
    scale = 0.1 / abs(result.u).max()
    deformed = mtri.Triangulation(*(result.points + scale * result.u).T, result.cells)
    fig, ax = plt.subplots(figsize=(7, 3.8))
    ax.triplot(triangles, lw=0.3, color="0.75")
    ax.triplot(deformed, lw=0.4, color="C0")
    ax.set(aspect="equal", title=f"Figure 2: deformed configuration (u x {scale:.3g})")
    fig.tight_layout()
    fig.savefig(args.out / "fig2-deformed.png", dpi=120)
    plt.close(fig)

    # Figure 3: the multipliers for F = 0.6
    multipliers(result, "Figure 3: multipliers for F = 0.6 (p = -2)", args.out / "fig3-multipliers.png")

    # Figure 4: the electric potential
    fig, ax = plt.subplots(figsize=(7, 3.8))
    contours = ax.tricontourf(triangles, result.phi, levels=20, cmap="viridis")
    fig.colorbar(contours, ax=ax, label=r"$\varphi$")
    ax.set(aspect="equal", title="Figure 4: electric potential")
    fig.tight_layout()
    fig.savefig(args.out / "fig4-potential.png", dpi=120)
    plt.close(fig)

    # Figures 5 and 6: the multipliers under larger loads
    for figure, load in [(5, -4.0), (6, -6.0)]:
        loaded = scene.copy()
        loaded.set("load.p", load)
        r = pc.run(loaded)
        multipliers(r, f"Figure {figure}: multipliers with load {load:g}", args.out / f"fig{figure}-multipliers.png")
        counts = r.report["contact"]
        print(f"load {load:g}: normal force {counts['normal_force']:.4f}, stick {counts['n_stick']}, slip {counts['n_slip']}")
    print(f"figures written to {args.out}/")


if __name__ == "__main__":
    main()
