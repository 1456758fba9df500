#!/usr/bin/python3
"""The pictures of docs/differentiable.md from a `pathlab optimize` output folder and a
`pathlab gradient` one: the progress strip, the loss and parameter curves, the forward-mode images.

usage: scripts/differentiable-figures.py OPTIMIZE_DIR TARGET_PNG GRADIENT_DIR OUT_DIR
       scripts/differentiable-figures.py --forward GRADIENT_DIR OUT_PNG   (the forward-mode strip alone)
(Debian's /usr/bin/python3 with matplotlib.)"""
import glob
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg
import matplotlib.pyplot as plt


def forward_strip(grad, out_png):
    """The image and dI/dtheta per parameter of a `pathlab gradient` folder, side by side."""
    images = [f"{grad}/primal.png"] + sorted(glob.glob(f"{grad}/d_*.png"))
    fig, ax = plt.subplots(1, len(images), figsize=(2.6 * len(images), 2.9))
    for a, f in zip(ax, images):
        a.imshow(mpimg.imread(f), interpolation="nearest")
        name = os.path.basename(f)[:-4]
        a.set_title("image" if name == "primal" else "dI/d " + name[2:], fontsize=7)
        a.axis("off")
    plt.tight_layout()
    plt.savefig(out_png, dpi=90)


if sys.argv[1] == "--forward":
    forward_strip(sys.argv[2], sys.argv[3])
    sys.exit(0)

opt, target, grad, out = sys.argv[1:5]
j = json.load(open(f"{opt}/loss.json"))
its = j["iterations"]

# Progress: the saved iterations, the final image, the target.
shown = [k for k in range(0, len(its), 10)][:: max(1, len(range(0, len(its), 10)) // 5)][:5]
fig, ax = plt.subplots(1, len(shown) + 2, figsize=(2.2 * (len(shown) + 2), 2.5))
for a, k in zip(ax, shown):
    a.imshow(mpimg.imread(f"{opt}/iteration_{k:04d}.png"), interpolation="nearest")
    a.set_title(f"iteration {k}\nloss {its[k]['loss']:.4f}", fontsize=8)
ax[-2].imshow(mpimg.imread(f"{opt}/final.png"), interpolation="nearest")
ax[-2].set_title(f"final ({len(its)} steps)", fontsize=8)
ax[-1].imshow(mpimg.imread(target), interpolation="nearest")
ax[-1].set_title("target", fontsize=8)
for a in ax:
    a.axis("off")
plt.tight_layout()
plt.savefig(f"{out}/progress.png", dpi=90)

# Loss and parameters per iteration.
fig, ax = plt.subplots(1, 2, figsize=(10, 3.6))
ax[0].semilogy([it["loss"] for it in its], color="#0072B2")
ax[0].set_xlabel("iteration")
ax[0].set_ylabel(f"{j['loss']} loss")
ax[0].set_title("loss (its floor: the noise of an 8 spp image against the target)", fontsize=9)
final = j["final"]["params"]
colours = ["#D55E00", "#009E73", "#0072B2"]
for name, style in zip(sorted(final), ["-", "--", ":"]):
    for c in range(3):
        ax[1].plot([it["params"][name][c] for it in its], style, color=colours[c], lw=1,
                   label=f"{name} {'RGB'[c]}" if name.startswith("light") or c == 0 else None)
ax[1].set_xlabel("iteration")
ax[1].set_title("parameters (R, G, B in red, green, blue)", fontsize=9)
ax[1].legend(fontsize=6)
plt.tight_layout()
plt.savefig(f"{out}/loss.png", dpi=90)

# Forward mode: dI/dtheta per parameter.
forward_strip(grad, f"{out}/forward.png")
