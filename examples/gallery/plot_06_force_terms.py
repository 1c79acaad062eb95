"""
Force-term sets: the thesis's law against gravity + static_v
============================================================

A scene lists the force terms that act on its body (:mod:`granrs.forces`). A vertical
drop feels no horizontal force and, in the thesis's law, its drag grows with
:math:`|e \\times v_E|`, which is zero when the rod moves along its axis; so for q = 0 the
full law and ``gravity`` + ``static_v`` should give the same impact, while each evaluation
of the smaller set does less work (terms not listed are neither evaluated nor stored). At
30 deg the drag and the horizontal term matter, and the sets part. Both sets take their
parameters from Table 3.4's vertical row.
"""

import matplotlib.pyplot as plt

import granrs
from granrs import forces

coef = granrs.coefficients.table_3_4(0.0)[0]
full = forces.thesis(coef)
reduced = [forces.gravity(), forces.static_v(eta_v=coef.eta_v, lam=coef.lam)]
print("full:   ", [t.name for t in full])
print("reduced:", [t.name for t in reduced])

fig, axes = plt.subplots(1, 2, figsize=(9.0, 3.8), sharey=True)
for ax, q_deg in zip(axes, (0.0, 30.0), strict=True):
    for label, terms, style in [("thesis's law", full, "-"), ("gravity + static_v", reduced, "--")]:
        scene = granrs.cases.free_link(
            q_deg=q_deg, v0=2.0, forces=terms, record=("state", "forces")
        )
        r = granrs.simulate(scene)
        ax.plot(r.series["t"] * 1e3, r.series["depth"] * 1e3, style, label=label)
        print(
            f"q = {q_deg:4.1f} deg, {label:20s}: t_s = {r.t_s * 1e3:6.2f} ms, depth = "
            f"{r.depth * 1e3:6.2f} mm, {r.summary['rhs_evals']} evaluations, terms {r.terms}"
        )
    ax.set_title(f"q = {q_deg:g} deg, v0 = 2 m/s")
    ax.set_xlabel("time [ms]")
axes[0].set_ylabel("depth of the tip [mm]")
axes[0].invert_yaxis()
axes[1].legend()
fig.tight_layout()
plt.show()

# %%
# Each term describes itself from the Rust core's registry:

for name in forces.TERMS:
    info = forces.info(name)
    params = ", ".join(f"{p.name} = {p.default:g} [{p.unit}]" for p in info.params) or "none"
    print(f"{name:14s} {info.equation}\n{'':14s} parameters: {params}")
