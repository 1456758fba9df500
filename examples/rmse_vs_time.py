#!/usr/bin/env python3
"""Equal-time comparison of estimators on course scenes, from Python.

Renders a reference of each scene, then each estimator for growing time budgets, and plots
the RMSE against the reference over render time (log-log) with matplotlib:

    PYTHONPATH=build/python python3 examples/rmse_vs_time.py -o docs/images/python/rmse-vs-time.png

Everything goes through pathlab's Python module (see docs/python.md): pathlab.load,
pathlab.render (float32 arrays), pathlab.rmse, pathlab.write.
"""
import argparse
import os
import time

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

import pathlab  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-o", "--output", default="rmse-vs-time.png", help="the plot (PNG)")
    ap.add_argument("--scenes", default="ceiling-diffuse,box-glossy", help="course scenes, comma-separated")
    ap.add_argument("--algorithms", default="pt-naive,pt-mis3,pt-mis,bdpt", help="estimators, comma-separated")
    ap.add_argument("--resolution", default="96x96", help="WxH")
    ap.add_argument("--budgets", default="0.125,0.25,0.5,1,2", help="seconds per render, comma-separated")
    ap.add_argument("--reference-spp", type=int, default=4096)
    ap.add_argument("--images", help="also write each scene's reference and last renders here (EXR)")
    args = ap.parse_args()
    width, height = map(int, args.resolution.split("x"))
    budgets = [float(b) for b in args.budgets.split(",")]
    scenes = args.scenes.split(",")
    algorithms = args.algorithms.split(",")

    fig, axes = plt.subplots(1, len(scenes), figsize=(5.2 * len(scenes), 4.2), squeeze=False)
    for ax, name in zip(axes[0], scenes):
        scene = pathlab.load(name)
        start = time.perf_counter()
        reference, reference_se = pathlab.render(scene, algorithm="pt-mis", spp=args.reference_spp, seed=99, resolution=(width, height))
        print(f"{name}: reference {args.reference_spp} spp in {time.perf_counter() - start:.1f} s", flush=True)
        if args.images:
            os.makedirs(args.images, exist_ok=True)
            pathlab.write(os.path.join(args.images, f"{name}-reference.exr"), reference)
        first_points, last_times = [], []
        for algorithm in algorithms:
            seconds, errors = [], []
            for budget in budgets:
                start = time.perf_counter()
                img, _ = pathlab.render(scene, algorithm=algorithm, time=budget, seed=1, resolution=(width, height))
                seconds.append(time.perf_counter() - start)
                errors.append(pathlab.rmse(img, reference, reference_se))
            print(f"  {algorithm:8s} RMSE " + " ".join(f"{e:.4f}" for e in errors), flush=True)
            ax.loglog(seconds, errors, marker="o", label=algorithm)
            first_points.append((seconds[0], errors[0]))
            last_times.append(seconds[-1])
            if args.images:
                pathlab.write(os.path.join(args.images, f"{name}-{algorithm}.exr"), img)
        # The Monte Carlo rate, error ~ time^-1/2, under the curves: from the lowest first point.
        t0, e0 = min(first_points, key=lambda p: p[1])
        t1 = max(last_times)
        ax.loglog([t0, t1], [e0 / 1.6, e0 / 1.6 * (t0 / t1) ** 0.5], "k--", linewidth=0.8, label="slope −1/2")
        for axis in (ax.xaxis, ax.yaxis):  # ticks at 1, 2, 5 x 10^k as plain numbers (0.05, 0.1, 0.2)
            axis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1, 2, 5)))
            axis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
            axis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_title(f"scene {scene.index} {name}, {width}x{height}")
        ax.set_xlabel("render time (s)")
        ax.set_ylabel("RMSE against the reference")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    if os.path.dirname(args.output):
        os.makedirs(os.path.dirname(args.output), exist_ok=True)
    fig.savefig(args.output, dpi=110)
    print(f"-> {args.output}")


if __name__ == "__main__":
    main()
