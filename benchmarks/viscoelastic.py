"""Benchmark: the viscoelastic substrate (standard linear solid) against its limits.

``python benchmarks/viscoelastic.py`` writes ``viscoelastic.md`` next to this file:

1. Lee-Radok creep of a Hertz contact: a sphere on an SLS half space (G0 = 1, G_inf = 0.5,
   tau = 0.5, so J grows from 1 to 2 with tau_c = 1) under a load ramped over t = 0.5 and
   held, beta = 2000 (near the dry limit), L = 3: the centre deflection against the
   elastic run's, vs ``(int J(t - s) dF(s) / F)^(2/3)``; coarse and medium meshes.
2. Relaxation time ladder on the paper's sliding sphere (t = 8, nearly steady sliding):
   G0 = 1, G_inf = 2/3 (J from 1 to 1.5); central and minimum film, friction, and the
   viscoelastic dissipation against the elastic runs with J = 1 (nu = 0.5) and J = 1.5
   (nu = 0.25), with the Deborah number ``De = 2 V tau_c / a`` (a = 1).
3. The inflow condition: the same at tau = 0.5 on L = 2, 3, 4.
4. Mesh convergence at tau = 0.5 (coarse, medium, fine) and the cost per step against
   the elastic run on the same mesh (one process, dense operator, threads pinned).
"""

from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402
from _machine import header  # noqa: E402

HERE = Path(__file__).resolve().parent


def sliding(substrate, mesh="coarse", L=2.0, dt=0.04, t_end=8.0):
    import femehl
    from femehl.problem.presets import paper_sphere
    from femehl.problem.scene import Domain
    from femehl.solver.energetics import sliding_energetics

    sc = dataclasses.replace(paper_sphere(), substrate=substrate, domain=Domain(L))
    t0 = time.perf_counter()
    r = femehl.solve(sc, t_end=t_end, dt=dt, method="fe", mesh=mesh, scheme="bdf2", estimate=False)
    wall = time.perf_counter() - t0
    e = sliding_energetics(r.disc, r.final, sc.fluid.beta)
    return {
        "film_center": float(r.film_center[-1]),
        "film_min": float(r.film_min[-1]),
        "load": float(r.load[-1]),
        "wall": wall,
        "steps": r.nsteps,
        "elements": r.info.get("elements"),
        **e,
    }


def lee_radok(mesh):
    from scipy.integrate import quad

    import femehl
    from femehl.problem.scene import Domain, Fluid, Motion, Scene, Sphere, Table
    from femehl.reference.theory import hertz_load

    tr, F = 0.5, float(hertz_load(1.0))
    sls = femehl.Viscoelastic(G0=1.0, G_inf=0.5, tau=0.5)
    out = {}
    for sub in (femehl.HalfSpace(), sls):
        sc = Scene(
            indenter=Sphere(),
            substrate=sub,
            fluid=Fluid(2000.0),
            motion=Motion(gap=0.1, load=Table((0.0, tr), (0.0, F))),
            domain=Domain(3.0),
        )
        r = femehl.solve(sc, t_end=8.0, dt=0.02, method="fe", mesh=mesh, scheme="bdf2", estimate=False)
        out[sub.kind] = (r.t, r.film_center - r.hc, r.film_min_at)
    rows = []
    t, ve, _ = out["viscoelastic"][0], out["viscoelastic"][1], None
    el = out["halfspace"][1]
    for ti in (0.5, 1.0, 2.0, 4.0, 8.0):
        i = int(np.argmin(abs(t - ti)))
        creep = quad(lambda s, tt=t[i]: sls.creep_compliance(tt - s) / tr, 0.0, min(t[i], tr))[0]
        pred = (creep / min(t[i] / tr, 1.0)) ** (2 / 3)
        rows.append((mesh, float(t[i]), float(el[i]), float(ve[i]), float(ve[i] / el[i]), pred))
    return rows


def main():
    import femehl

    lines = ["# Viscoelastic substrate (standard linear solid)", "", header("viscoelastic.py"), ""]
    # 1. Lee-Radok
    lr = lee_radok("coarse") + lee_radok("medium")
    lines += [
        "## 1. Lee-Radok creep of a Hertz contact under constant load",
        "",
        "Sphere on an SLS half space (G0 = 1, G_inf = 0.5, tau = 0.5: J(t) = 2 - exp(-t)), beta "
        "= 2000, L = 3, load ramped to the Hertz load of delta = 1 over t = 0.5 and held; BDF2, "
        "dt = 0.02. Centre deflection (= the Hertz approach delta in the dry limit) of the "
        "viscoelastic and the elastic runs; Lee and Radok (1960): delta^(3/2) is proportional "
        "to int J(t - s) dF(s), so the ratio is (int J dF / F)^(2/3). The contact radius "
        "follows as a = sqrt(delta) (R = 1).",
        "",
        "| mesh | t | elastic deflection | viscoelastic deflection | ratio | Lee-Radok | error |",
        "|---|---|---|---|---|---|---|",
    ]
    for mesh, t, el, ve, ratio, pred in lr:
        err = ratio / pred - 1
        lines.append(f"| {mesh} | {t:g} | {el:.4f} | {ve:.4f} | {ratio:.4f} | {pred:.4f} | {err:+.2%} |")
    print("\n".join(lines[-len(lr) :]), flush=True)
    # 2. tau ladder
    glassy, rubbery = sliding(femehl.HalfSpace()), sliding(femehl.HalfSpace(nu=0.25))
    taus = [1e-3, 1e-2, 0.1, 0.3, 1.0, 3.0, 10.0, 100.0, 1000.0]
    rows = []
    for tau in taus:
        s = femehl.Viscoelastic(G0=1.0, G_inf=1 / 1.5, tau=tau)
        rows.append((tau, s.tau_creep, sliding(s)))
        print(tau, rows[-1][2], flush=True)
    lines += [
        "",
        "## 2. Relaxation time: from the relaxed to the unrelaxed solid",
        "",
        "The paper's sphere (beta = 200, L = 2, indentation to hc = -1 then tanh sliding start) "
        "at t = 8 (V = 1 - 2e-6), coarse mesh, BDF2, dt = 0.04; G0 = 1, G_inf = 2/3 (J from 1 to "
        "1.5). De = 2 V tau_c / a with a = 1. Friction and powers in femehl's units "
        "(femehl.solver.energetics; mu = friction/load sqrt(h_inf/R)). The share is the viscoelastic "
        "dissipation's of the friction work f V; 'balance' is (f V - D_film - P) / (f V).",
        "",
        "| tau | De | film centre | film min | load | friction | D_film | P_solid | share | balance |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]

    def row(name, de, r):
        work = r["friction"]
        bal = (work - r["dissipation_film"] - r["power_sliding"]) / work
        return (
            f"| {name} | {de} | {r['film_center']:.5f} | {r['film_min']:.5f} | {r['load']:.5f} | "
            f"{r['friction']:.5f} | {r['dissipation_film']:.5f} | {r['power_sliding']:.2e} | "
            f"{r['power_sliding'] / work:.1%} | {bal:.1e} |"
        )

    lines.append(row("relaxed elastic (J = 1.5)", "0", rubbery))
    for tau, tc, r in rows:
        lines.append(row(f"{tau:g}", f"{2 * tc:.3g}", r))
    lines.append(row("unrelaxed elastic (J = 1)", "inf", glassy))
    lines += [
        "",
        f"At tau = 1e-3 the central film is {rows[0][2]['film_center'] / rubbery['film_center'] - 1:+.2%} "
        f"from the relaxed elastic run's and at tau = 1000 "
        f"{rows[-1][2]['film_center'] / glassy['film_center'] - 1:+.2%} from the unrelaxed one's.",
    ]
    # 3. inflow
    lines += [
        "",
        "## 3. The inflow condition (domain size)",
        "",
        "Material entering the domain upstream carries the memory of the rim (see the module "
        "docstring). tau = 0.5 (De = 1.5), coarse ladder on L = 2, 3, 4, t = 8, dt = 0.04. "
        "The friction grows with L mostly by the Couette shear V/(6 beta d) of the thick film "
        "far from the contact (its integral grows like log L, as for an elastic substrate): "
        "it is the friction of the whole lubricated disk. The viscoelastic dissipation P_solid "
        "is the inflow condition's measure: 9 % from L = 2 to 3, 2 % from 3 to 4.",
        "",
        "| L | elements | film centre | film min | friction | P_solid |",
        "|---|---|---|---|---|---|",
    ]
    s = femehl.Viscoelastic(G0=1.0, G_inf=1 / 1.5, tau=0.5)
    for L in (2.0, 3.0, 4.0):
        r = sliding(s, L=L)
        lines.append(
            f"| {L:g} | {r['elements']} | {r['film_center']:.5f} | {r['film_min']:.5f} | "
            f"{r['friction']:.5f} | {r['power_sliding']:.5f} |"
        )
        print(lines[-1], flush=True)
    # 4. mesh convergence and cost
    lines += [
        "",
        "## 4. Mesh convergence and cost per step",
        "",
        "tau = 0.5, L = 2, t = 8, dt = 0.04, BDF2, dense operator, one thread; the elastic "
        "(J = 1) run on the same mesh in the same process for the cost ratio (noisy when another "
        "process shares the machine).",
        "",
        "| mesh | elements | film centre | film min | friction | P_solid | s/step | elastic s/step | ratio |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for mesh in ("coarse", "medium", "fine"):
        v, e = sliding(s, mesh=mesh), sliding(femehl.HalfSpace(), mesh=mesh)
        lines.append(
            f"| {mesh} | {v['elements']} | {v['film_center']:.5f} | {v['film_min']:.5f} | "
            f"{v['friction']:.5f} | "
            f"{v['power_sliding']:.5f} | {v['wall'] / v['steps']:.4f} | {e['wall'] / e['steps']:.4f} | "
            f"{(v['wall'] / v['steps']) / (e['wall'] / e['steps']):.2f} |"
        )
        print(lines[-1], flush=True)
    (HERE / "viscoelastic.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
