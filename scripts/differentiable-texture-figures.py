#!/usr/bin/python3
"""The pictures of the texture half of docs/differentiable.md's worked example, from a
`pathlab optimize` output folder: the progress (textures above, renders below: the truth and the
target, the start, a few iterations, the result) and the loss curve (optimize's own loss.svg,
copied). Prints the recovered texels' error against the true texture.

usage: scripts/differentiable-texture-figures.py OPTIMIZE_DIR TARGET_PNG TRUE_TEXTURE_PNG OUT_DIR
(Debian's /usr/bin/python3 with numpy and matplotlib.)"""
import json
import shutil
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg
import matplotlib.pyplot as plt
import numpy as np

opt, target, truth, out = sys.argv[1:5]
j = json.load(open(f"{opt}/loss.json"))
its = j["iterations"]
name = next(n for n in j["final"]["params"] if n.endswith(".data"))


def srgb_to_linear(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


# The true texels as pathlab reads them (the PNG's sRGB decoded to linear), and the result.
true_texels = srgb_to_linear(mpimg.imread(truth)[..., :3].astype(np.float64))
result = np.array(j["final"]["params"][name]).reshape(true_texels.shape)
start = 0.5
rms = lambda x: float(np.sqrt(np.mean((x - true_texels) ** 2)))
print(f"{name}: texel RMS error {rms(np.full_like(true_texels, start)):.4f} at the start, {rms(result):.4f} after {len(its)} "
      f"iterations; median absolute error {float(np.median(np.abs(result - true_texels))):.4f}")

shown = [k for k in (0, 10, 30, 100) if k < len(its)]
cols = len(shown) + 2
fig, ax = plt.subplots(2, cols, figsize=(1.45 * cols, 3.2))
ax[0, 0].imshow(mpimg.imread(truth), interpolation="nearest")
ax[0, 0].set_title("true texture", fontsize=7)
ax[1, 0].imshow(mpimg.imread(target), interpolation="nearest")
ax[1, 0].set_title("target", fontsize=7)
for c, k in enumerate(shown, 1):
    ax[0, c].imshow(mpimg.imread(f"{opt}/{name}_{k:04d}.png"), interpolation="nearest")
    ax[0, c].set_title("start (grey)" if k == 0 else f"iteration {k}", fontsize=7)
    ax[1, c].imshow(mpimg.imread(f"{opt}/iteration_{k:04d}.png"), interpolation="nearest")
    ax[1, c].set_title(f"loss {its[k]['loss']:.4f}", fontsize=7)
ax[0, -1].imshow(mpimg.imread(f"{opt}/{name}.png"), interpolation="nearest")
ax[0, -1].set_title(f"result ({len(its)} steps)", fontsize=7)
ax[1, -1].imshow(mpimg.imread(f"{opt}/final.png"), interpolation="nearest")
ax[1, -1].set_title(f"loss {j['final']['loss']:.4f}", fontsize=7)
for a in ax.flat:
    a.axis("off")
plt.tight_layout()
plt.savefig(f"{out}/texture-progress.png", dpi=80)
# 256 colours: the noisy renders compress poorly otherwise.
from PIL import Image

Image.open(f"{out}/texture-progress.png").convert("RGB").quantize(256).save(f"{out}/texture-progress.png", optimize=True)
shutil.copy(f"{opt}/loss.svg", f"{out}/texture-loss.svg")
