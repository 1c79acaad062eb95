"""
Work-precision: what accuracy costs
===================================

The work-precision diagram of ``granrs bench accuracy`` (``docs/accuracy/accuracy.csv``,
measured once and committed; re-running it takes minutes): for a vertical, a 45 deg and an
85 deg drop, the error in depth against a reference at dt = 1e-7 s, for RK4 in each sign
model over dt = 1e-3 ... 1e-6 s and for the adaptive Dormand-Prince 5(4) over rtol =
1e-3 ... 1e-12. Settings that did not stop are left out (the vertical drop never stops
with the ``smooth`` sign).
"""

from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd

try:
    here = Path(__file__).resolve().parent
except NameError:  # run in a notebook
    here = Path.cwd()
data = pd.read_csv(here.parents[1] / "docs" / "accuracy" / "accuracy.csv")
ok = data[~data["failed"]]
print(ok.groupby(["scene", "label"])["depth_rel_err"].min().unstack().to_string())

# %%
# Error against right-hand-side evaluations (a machine-independent cost) per scene.

styles = {
    "rk4 modes": ("C0", "o"),
    "rk4 raw": ("C1", "s"),
    "rk4 smooth": ("C2", "^"),
    "dopri5": ("C3", "D"),
}
scenes = list(dict.fromkeys(ok["scene"]))
fig, axes = plt.subplots(1, len(scenes), figsize=(10.0, 3.6), sharey=True)
for ax, name in zip(axes, scenes, strict=True):
    for label, (colour, marker) in styles.items():
        part = ok[(ok["scene"] == name) & (ok["label"] == label)].sort_values("rhs_evals")
        err = part["depth_rel_err"].clip(lower=1e-16)
        ax.loglog(part["rhs_evals"], err, marker=marker, color=colour, label=label, ms=4)
    ax.set_title(name)
    ax.set_xlabel("rhs evaluations")
    ax.grid(True, which="major", alpha=0.3)
axes[0].set_ylabel("relative depth error")
axes[-1].legend(fontsize=8)
fig.tight_layout()
plt.show()

# %%
# At the thesis's 10 kHz the default ``modes`` is within about 2e-8 in depth in all three
# scenes; ``raw`` (the thesis's plain ``sign()``) is about 1000 times worse on the vertical
# drop. See :doc:`/events` and :doc:`/accuracy/accuracy` for the numbers.
