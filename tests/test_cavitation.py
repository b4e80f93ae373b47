"""The Reynolds (Swift-Stieber) cavitation condition p >= 0, its set lagged one step.

The independent reference: the steady rigid parabolic slider ``d = hc + x^2/2`` with the
Reynolds exit condition ``p = dp/dx = 0`` at the cavitation point ``x_c``: from the inlet
``x = L`` the pressure is ``p(x) = (V/beta) int_x^L (d - d*)/d^3`` and ``p = 0`` beyond;
``p'(x_c) = 0`` makes ``d(x_c) = d*``, and ``p(x_c) = 0`` fixes ``d*`` (quadrature and a
root, scipy).
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.integrate import quad
from scipy.optimize import brentq

import femehl
from femehl.errors import SceneError
from femehl.problem.cavitation import SET_BAND, ReynoldsCavitation
from femehl.problem.line import LineScene
from femehl.problem.scene import Constant, Fluid, Motion
from femehl.solver.energetics import FRICTION_COLUMNS
from femehl.solver.stepping import State

HC, BETA, L, V = 0.2, 10.0, 2.0, 1.0


def _d(x):
    return HC + x * x / 2


def _slider():
    def gap(ds):
        xc = -math.sqrt(2 * (ds - HC))
        return quad(lambda x: (_d(x) - ds) / _d(x) ** 3, xc, L, limit=200)[0]

    ds = brentq(gap, HC * (1 + 1e-7), _d(L) * 0.999, xtol=1e-15)
    xc = -math.sqrt(2 * (ds - HC))

    def p(x):
        return np.array(
            [
                (V / BETA) * quad(lambda s: (_d(s) - ds) / _d(s) ** 3, xi, L, limit=200)[0]
                if xi > xc
                else 0.0
                for xi in x
            ]
        )

    return xc, p


def _line(n, cavitation="reynolds", t_end=3.0):
    sc = LineScene(
        k=1e9, beta=BETA, motion=Motion(gap=Constant(HC), velocity=Constant(V)), L=L, cavitation=cavitation
    )
    return femehl.solve(sc, t_end=t_end, dt=0.05, n_elements=n, estimate=False, linear_solver="lu")


def test_rigid_slider_against_the_reynolds_exit_condition():
    """Steady: the pressure and the cavitated length converge to the reference (measured
    error 4.9e-4, 7.6e-5, 4.4e-5 at 100, 200, 400 elements); no pressure below 0."""
    xc, pref = _slider()
    errs = []
    for n in (100, 200, 400):
        res = _line(n)
        assert np.max(np.abs(res.states[-1].p - res.states[-2].p)) == 0.0  # the set settled
        x, p = res.disc.x, res.final.p
        errs.append(np.max(np.abs(p - pref(x))) / pref(x).max())
        assert p.min() >= -1e-14
        h = 2 * L / n
        assert res.final.info["cavitated_area"] == pytest.approx(xc + L, abs=2 * h)
    assert errs[0] < 1e-3 and errs[2] < 0.2 * errs[0]


def test_full_sommerfeld_is_unchanged():
    """cavitation=None assembles nothing new: the same run as before (and it goes negative)."""
    a = _line(100, cavitation=None, t_end=0.5)
    sc = LineScene(k=1e9, beta=BETA, motion=Motion(gap=Constant(HC), velocity=Constant(V)), L=L)
    b = femehl.solve(sc, t_end=0.5, dt=0.05, n_elements=100, estimate=False, linear_solver="lu")
    assert np.array_equal(a.final.p, b.final.p) and a.final.p.min() < -0.01


def test_paper_case_with_cavitation():
    """The soft sphere: a thicker minimum film than full Sommerfeld's (medium mesh to t = 5:
    0.02801 against 0.02631, measured) and a cavitated area behind the contact.  A node
    that cavitates is negative for the one step before it joins the set: that transient
    is first order in dt (measured -0.22 %, -0.12 %, -0.063 % of the peak pressure at
    dt = 0.02, 0.01, 0.005 on the coarse mesh)."""
    sc = femehl.presets.paper_sphere()
    cav = dataclasses.replace(sc, fluid=Fluid(sc.fluid.beta, cavitation="reynolds"))
    opts = dict(t_end=3.0, mesh="coarse", scheme="bdf2", estimate=False, store_every=1)
    full = femehl.solve(sc, dt=0.02, **opts)
    runs = [femehl.solve(cav, dt=dt, **opts) for dt in (0.02, 0.01)]
    res = runs[0]
    neg = [-min(s.p.min() for s in r.states) / r.p_max.max() for r in runs]
    assert 0 <= neg[0] < 3e-3 and neg[0] / neg[1] > 1.6
    assert res.film_min[-1] > 1.02 * full.film_min[-1]
    assert res.final.info["cavitated_area"] > 0.5
    assert res.final.film_min_at[0] < 0  # still at the exit side


def test_resume_keeps_the_cavitated_set(tmp_path):
    from femehl.api import run_to_folder

    sc = LineScene(
        k=1e9, beta=BETA, motion=Motion(gap=Constant(HC), velocity=Constant(V)), L=L, cavitation="reynolds"
    )
    opts = dict(dt=0.05, n_elements=100, linear_solver="lu", log=lambda *a: None, checkpoint_every=5)
    whole = run_to_folder(sc, tmp_path / "a", t_end=1.0, **opts)
    run_to_folder(sc, tmp_path / "b", t_end=0.5, **opts)
    resumed = run_to_folder(sc, tmp_path / "b", t_end=1.0, resume=True, **opts)
    assert np.array_equal(resumed.final.p, whole.final.p)


def test_bad_cavitation_and_fd_and_toml(tmp_path):
    with pytest.raises(SceneError, match="cavitation must be None"):
        Fluid(200.0, cavitation="jfo-typo")
    sc = dataclasses.replace(femehl.presets.paper_sphere(), fluid=Fluid(200.0, cavitation="reynolds"))
    with pytest.raises(SceneError, match="method='fe'"):
        femehl.solve(sc, t_end=0.1, dt=0.05, method="fd", dr=0.1, dtheta=math.pi / 12)
    from femehl.problem.scenefile import load_scene_file

    src = (pathlib.Path(__file__).parents[1] / "examples" / "paper_sphere.toml").read_text()
    f = tmp_path / "s.toml"
    f.write_text(src.replace("[fluid]\n", '[fluid]\ncavitation = "reynolds"\n'))
    assert load_scene_file(f)[0].cavitation == "reynolds"


def test_series_and_maps_show_the_cavitated_region(tmp_path):
    """The VTK series carries ``cavitated`` (1 where p is held at 0, mirrored with the half
    disk), and the maps hatch that region instead of drawing a p = 0 contour."""
    import matplotlib

    matplotlib.use("Agg")
    import meshio

    from femehl.output import plots
    from femehl.output.snapshot import read_snapshot

    sc = femehl.presets.paper_sphere()
    cav = dataclasses.replace(sc, fluid=Fluid(sc.fluid.beta, cavitation="reynolds"))
    res = femehl.solve(cav, t_end=2.5, dt=0.05, mesh="coarse", scheme="bdf2", estimate=False, store_every=10)
    res.save(tmp_path)
    m = meshio.read(sorted(tmp_path.glob("fields_*.vtu"))[-1])
    flag = m.point_data["cavitated"]
    assert set(np.unique(flag)) == {0.0, 1.0}
    # held at 0 (to the Krylov tolerance), or joining the set after its one negative step
    p = m.point_data["pressure"]
    assert np.max(np.abs(p[flag == 1.0])) <= 3e-3 * p.max()
    assert np.all(p[flag == 0.0] >= -1e-12 * p.max())
    y = m.points[:, 1]
    assert flag[y > 1e-9].sum() == flag[y < -1e-9].sum()  # the image carries the same set
    snap = read_snapshot(tmp_path)
    fig = plots.maps_figure(snap)
    p_ax = fig.get_axes()[1]
    labels = [h.get_label() for h in p_ax.get_legend_handles_labels()[0]]
    assert "cavitated (p = 0)" in labels and "p = 0" not in labels
    matplotlib.pyplot.close(fig)
    full = femehl.solve(sc, t_end=0.2, dt=0.1, mesh="coarse", estimate=False)
    full.save(tmp_path / "full")
    assert "cavitated" not in meshio.read(sorted((tmp_path / "full").glob("fields_*.vtu"))[-1]).point_data


# ---- half-Sommerfeld and the per-step figures ---------------------------------------------
def _p1_integral(disc, p_nodes):
    """``int p dA`` of a nodal P1 field over the mesh triangles (whole plane): a triangle
    integrates a linear field to its area times the mean of its vertex values."""
    pts, t = disc.mesh.p, disc.mesh.t
    a, b, c = (pts[:, t[k]] for k in range(3))
    area = 0.5 * np.abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
    return (2.0 if disc.half else 1.0) * float(np.sum(area * p_nodes[t].mean(axis=0)))


def test_half_sommerfeld_is_the_full_run_clipped():
    """Node by node the pressure is max(full-Sommerfeld p, 0), the film and deflection are
    full Sommerfeld's (bit for bit: same system, direct solver), the load is the clipped
    field's integral (by triangles, independently of the load weights) and ``load_full``
    the full run's load; the cavitated area is the area of the clipped nodes' dual cells."""
    sc = femehl.presets.paper_sphere()
    hs = dataclasses.replace(sc, fluid=Fluid(sc.fluid.beta, cavitation="half-sommerfeld"))
    opts = dict(t_end=2.5, dt=0.05, mesh="coarse", estimate=False, store_every=10, linear_solver="lu")
    full, half = femehl.solve(sc, **opts), femehl.solve(hs, **opts)
    assert len(full.states) == len(half.states) == 6
    disc = half.disc
    pts, t = disc.mesh.p, disc.mesh.t
    a, b, c = (pts[:, t[k]] for k in range(3))
    area = 0.5 * np.abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
    dual = np.zeros(pts.shape[1])
    np.add.at(dual, t.ravel(), np.tile(area / 3.0, 3))  # t.ravel() is row-major: vertex k of all
    for f, s in zip(full.states, half.states, strict=True):
        assert np.array_equal(s.d, f.d) and np.array_equal(s.w, f.w) and s.film_min == f.film_min
        assert np.array_equal(s.p, np.maximum(f.p, 0.0))
        assert s.load == pytest.approx(_p1_integral(disc, s.p), rel=1e-12)
        assert s.info["load_full"] == pytest.approx(f.load, rel=1e-12)
        assert s.info["cavitated_area"] == pytest.approx(2.0 * dual[f.p < 0].sum(), rel=1e-12, abs=1e-14)
        assert s.p_max == f.p_max
    assert half.load[-1] > 1.03 * full.load[-1]  # the sub-ambient lobe no longer subtracts
    assert half.cavitated_area[-1] > 1.0 and np.isnan(getattr(full, "cavitated_area", np.nan))
    assert half.info["cavitation"] == "half-sommerfeld" and "clipped" in half.info["cavitation_note"]
    dim = femehl.Dimensional(R=5e-3, G=1e5, eta=0.1, V_ss=1e-3, h_inf=2e-5, nu=0.5)
    si, si_full = dim.result_table(half), dim.result_table(full)
    assert np.allclose(si["cavitated_area"], half.cavitated_area * dim.length**2, rtol=1e-14)
    assert np.allclose(si["load_full"], si_full["load"], rtol=1e-12) and "load_full" not in si_full


def test_half_sommerfeld_line_area_fd_and_refusals(tmp_path):
    """1-D: the cavitated length is where the full-Sommerfeld pressure is negative (its
    zero crossing, interpolated, to the outlet); adaptive steps are the full run's; the FD
    reference takes half-Sommerfeld (post-processing) but not Reynolds; an imposed load
    is refused with half-Sommerfeld (the load row would balance the unclipped pressure)."""
    full, half = _line(200, cavitation=None, t_end=1.0), _line(200, cavitation="half-sommerfeld", t_end=1.0)
    x, p = full.disc.x, full.final.p
    assert np.array_equal(half.final.p, np.maximum(p, 0.0))
    k = np.flatnonzero((p[:-1] < 0) & (p[1:] >= 0))[-1]  # the last crossing from below
    x0 = x[k] - p[k] * (x[k + 1] - x[k]) / (p[k + 1] - p[k])
    assert half.final.info["cavitated_area"] == pytest.approx(x0 + L, abs=2 * np.diff(x).max())
    sc = LineScene(k=1e9, beta=BETA, motion=Motion(gap=Constant(HC), velocity=Constant(V)), L=L)
    opts = dict(t_end=1.0, step_tol=1e-3, n_elements=100, estimate=False, linear_solver="lu")
    a = femehl.solve(sc, **opts)
    b = femehl.solve(
        dataclasses.replace(sc, fluid=Fluid(sc.fluid.beta, cavitation="half-sommerfeld")), **opts
    )
    assert np.array_equal(a.t, b.t)
    paper = femehl.presets.paper_sphere()
    fd = dict(t_end=0.2, dt=0.1, method="fd", dr=0.1, dtheta=math.pi / 12)
    f = femehl.solve(paper, **fd)
    h = femehl.solve(dataclasses.replace(paper, fluid=Fluid(200.0, cavitation="half-sommerfeld")), **fd)
    assert np.array_equal(h.final.p, np.maximum(f.final.p, 0.0)) and np.array_equal(h.final.d, f.final.d)
    with pytest.raises(SceneError, match="post-processing of an imposed-gap run"):
        femehl.Scene(fluid=Fluid(200.0, cavitation="half-sommerfeld"), motion=Motion(gap=0.1, load=0.3))
    with pytest.raises(SceneError, match='cavitation="reynolds"'):
        LineScene(
            motion=Motion(gap=Constant(HC), velocity=Constant(V)), load=0.5, cavitation="half-sommerfeld"
        )
    from femehl.problem.scenefile import load_scene_file

    src = (pathlib.Path(__file__).parents[1] / "examples" / "paper_sphere.toml").read_text()
    toml = tmp_path / "s.toml"
    toml.write_text(src.replace("[fluid]\n", '[fluid]\ncavitation = "half-sommerfeld"\n'))
    assert load_scene_file(toml)[0].cavitation == "half-sommerfeld"
    from femehl.studies.sweeps import SweepError, plan_sweep

    run = {"t_end": 0.2, "dt": 0.1, "mesh": "coarse"}
    plan = plan_sweep(None, {"fluid.cavitation": [None, "reynolds", "half-sommerfeld"]}, run=run)
    assert [c.scene.cavitation for c in plan.cases] == [None, "reynolds", "half-sommerfeld"]
    with pytest.raises(SweepError, match="imposed-gap run"):
        plan_sweep(None, {"fluid.cavitation": ["half-sommerfeld"], "motion.load": [0.3]}, run=run)


def test_full_film_source_closes_the_flux_balance():
    """The Reynolds condition's ``full_film_source`` is the flux balance of the fields, computed
    element by element: ``d/dt int psi d + J(L) - J(-L)`` with the element fluxes
    ``J = -beta d*^3 p' - V d`` (``d*`` the lagged film of the step, ``psi`` the sum of the
    free hat functions: half weight on the end elements) -- to round-off, while the set
    moves and at the steady state.  There the cavity opens to the outlet: the full-film
    volume the condition supplies is the gap's Couette flux leaving minus that at rupture,
    ``V (d(-L) - d_c)``, to the size of the end element (it converges to it)."""
    xc, _ = _slider()
    d_c = _d(xc)
    errs = []
    for n in (100, 400):
        res = _line(n)
        x = res.disc.x
        h = np.diff(x)
        psi = h.copy()
        psi[[0, -1]] *= 0.5
        for k in (2, 6, len(res.states) - 1):
            s0, s1 = res.states[k - 1], res.states[k]
            J = -BETA * s0.d**3 * np.diff(s1.p) / h - V * s1.d
            balance = np.sum(psi * (s1.d - s0.d)) / (s1.t - s0.t) + J[-1] - J[0]
            assert s1.info["full_film_source"] == pytest.approx(balance, rel=1e-10)
        assert res.full_film_source[-1] == pytest.approx(V * (res.final.d[0] - d_c), rel=2e-3)
        errs.append(abs(res.full_film_source[-1] - V * (_d(-L) - d_c)))
    assert errs[1] < 0.3 * errs[0] and errs[1] < 0.01 * V * (_d(-L) - d_c)


def test_summary_columns_series_and_restart(tmp_path):
    """summary.csv: full Sommerfeld keeps exactly its columns; a condition adds its own
    (the Result's arrays); the half-Sommerfeld series is labelled; a resumed run writes
    the same table as the whole run."""
    from femehl.api import run_to_folder
    from femehl.output.series import field_value
    from femehl.output.table import COLUMNS, read_summary

    base = dict(k=1e9, beta=BETA, motion=Motion(gap=Constant(HC), velocity=Constant(V)), L=L)
    opts = dict(dt=0.05, n_elements=100, linear_solver="lu", log=lambda *a: None, checkpoint_every=5)
    cols = {}
    for cav in (None, "reynolds", "half-sommerfeld"):
        sc = LineScene(**base, cavitation=cav)
        whole = run_to_folder(sc, tmp_path / f"{cav}-a", t_end=1.0, **opts)
        run_to_folder(sc, tmp_path / f"{cav}-b", t_end=0.5, **opts)
        run_to_folder(sc, tmp_path / f"{cav}-b", t_end=1.0, resume=True, **opts)
        a, b = (read_summary(tmp_path / f"{cav}-{s}" / "summary.csv") for s in "ab")
        cols[cav] = tuple(c for c in a if not c.startswith("err_"))
        for c in cols[cav]:
            assert np.array_equal(a[c], b[c]), c
        for c in cols[cav][len(COLUMNS) :]:
            assert np.allclose(a[c], getattr(whole, c), rtol=1e-9, atol=1e-12)
        vtu = sorted((tmp_path / f"{cav}-a").glob("fields_*.vtu"))[-1]
        assert field_value(vtu, "HalfSommerfeldClipped") == (1.0 if cav == "half-sommerfeld" else None)
    assert cols[None] == COLUMNS + FRICTION_COLUMNS
    assert cols["reynolds"] == COLUMNS + ("cavitated_area", "full_film_source") + FRICTION_COLUMNS
    assert cols["half-sommerfeld"] == COLUMNS + ("load_full", "cavitated_area") + FRICTION_COLUMNS
    text = sorted((tmp_path / "half-sommerfeld-a").glob("fields_*.vtu"))[-1].read_text(errors="ignore")
    assert "half-Sommerfeld: negative pressures clipped after the solve" in text


def _two_constrictions_gap(x):
    return 0.5 * x * x - 0.7 * np.exp(-(((x + 1.2) / 0.2) ** 2))


def _TwoConstrictions(**kw):  # noqa: N802 - a scene kind, as LineScene
    """The cylinder with a bump downstream of its minimum (at x = -1.2, film 0.22): the film
    ruptures behind the minimum and reforms at the bump -- a cavity inside the domain."""
    return LineScene(profile=_two_constrictions_gap, **kw)


def test_full_film_source_of_a_closed_cavity_is_the_liquid_created_where_the_film_reforms():
    """Steady, two cavities: one closed between the minimum and the bump, one open to the
    outlet.  In the film regions the flux ``-J`` is one constant each (``q1`` upstream,
    ``q2`` between the cavities).  The closed cavity's multipliers sum to ``q2 - q1``: the
    liquid entering it at rupture is ``q1`` (the Couette flux of the film there, ``dp/dx =
    0``: nothing created at rupture), the film after it carries ``q2``, so ``q2 - q1`` is
    what the condition creates where the film reforms.  The open cavity's sum is ``V d(-L)
    - q2``, the gap's Couette flux leaving minus the liquid's: gas."""
    sc = _TwoConstrictions(
        k=1e9, beta=BETA, motion=Motion(gap=Constant(HC), velocity=Constant(V)), L=L, cavitation="reynolds"
    )
    res = femehl.solve(
        sc, t_end=4.0, dt=0.05, n_elements=400, grading="uniform", estimate=False, linear_solver="lu"
    )
    s, disc = res.final, res.disc
    assert np.array_equal(res.states[-2].p, s.p)  # steady: the set and the field settled
    x, h = disc.x, np.diff(disc.x)
    lam = np.where(s.own["p_aux"] < 0, -s.own["p_aux"], 0.0)  # the multipliers of the held (free) nodes
    held = disc.expand((s.own["p_aux"] < 0).astype(float)) > 0
    J = -BETA * s.d**3 * np.diff(s.p) / h - V * s.d  # element fluxes (steady: d* = d)
    lam_nodes = disc.expand(lam)
    exit_ = held & (x < -1.0)
    closed = held & (x > -1.0)
    assert exit_.any() and closed.any() and x[closed].max() < 0 < x[~held].max()
    film = ~(held[:-1] | held[1:])  # elements between free, not held nodes
    xe = 0.5 * (x[:-1] + x[1:])
    up, between = film & (xe > x[closed].max()), film & (xe < x[closed].min()) & (xe > x[exit_].max())
    q1, q2 = -J[up], -J[between]
    assert np.ptp(q1) < 1e-10 * q1.mean() and np.ptp(q2) < 1e-10 * q2.mean()  # conserved
    q1, q2 = q1.mean(), q2.mean()
    assert lam_nodes[closed].sum() == pytest.approx(q2 - q1, rel=1e-9)
    assert lam_nodes[exit_].sum() == pytest.approx(V * s.d[0] - q2, rel=1e-9)
    assert s.info["full_film_source"] == pytest.approx(V * s.d[0] - q1, rel=1e-9)
    assert abs(q2 - q1) > 0.01 * q1  # the Reynolds condition does create (or destroy) liquid
    k = int(np.flatnonzero(closed)[-1])  # the rupture: the film's flux is its Couette flux
    assert q1 == pytest.approx(V * s.d[k], rel=0.02)


def test_impulsive_start_with_a_lagged_set_in_the_automatic_mode():
    """Sliding at V = 1 from t = 0 on a Winkler foundation (k = 100) with the Reynolds
    condition, no mesh and no dt.  The first step is solved before the cavitated set exists
    (full Sommerfeld: its load about 0 whatever the step), so the adaptive steps judge the
    load from the other levels (``info["load_unsettled"]``); before, every trial down to
    the step floor had its load judged against that level and the run stopped at
    t = 5e-10.  Measured at t = 4 against the exact steady Reynolds solution
    (femehl.reference.line_jfo_steady): load 1.5e-4, minimum film 1.1e-5 off; tolerance
    1e-3 (the automatic mode's 1e-2 with a margin for the estimate's coarse companions)."""
    from femehl.reference.line_jfo_steady import steady_reynolds

    ref = steady_reynolds(lambda x: 0.5 * x * x, 0.1, V=1.0, beta=10.0, k=100.0, L=2.0)
    sc = LineScene(k=100.0, beta=10.0, motion=Motion(gap=0.1, velocity=1.0), cavitation="reynolds")
    r = femehl.solve(sc, t_end=4.0)
    assert r.load[-1] == pytest.approx(ref.load, rel=1e-3)
    assert r.film_min[-1] == pytest.approx(ref.film_min, rel=1e-3)


def test_a_node_within_round_off_of_zero_keeps_its_side_of_the_set():
    """Reynolds: the next set is ``{y < 0}`` but a node whose ``y`` is within ``SET_BAND`` of
    the largest ``|y|`` (1e-6 of it: the solve's round-off, as where asperities carry the
    load and the film's pressure is noise) keeps its side: a free node at -3e-7 stays free,
    a held node whose multiplier is 3e-7 stays held; outside the band the sign decides."""
    free_p = np.array([1.0, 0.5, 3e-7, -3e-7, -0.2])  # free nodes 0-4: p
    held_rhs = np.array([3e-7, 0.1])  # held nodes 5, 6: y = -(D p - rhs) = rhs (p = 0 there)
    n = free_p.size + held_rhs.size
    p = np.concatenate([free_p, np.zeros(2)])
    fixed = np.array([5, 6])
    op = SimpleNamespace(D=sp.identity(n, format="csr"), G=sp.csr_matrix((n, 1)))
    rhs = np.concatenate([np.zeros(free_p.size), held_rhs])
    state = SimpleNamespace(own={"p_aux": np.zeros(n)})
    solved = SimpleNamespace(op=op, rhs=rhs, p=p, aux=fixed, scale=1.0, state=state)
    stepper = SimpleNamespace(film_pressure=lambda new, p: p, g=np.ones(n), disc=None)
    new = State(
        step=1,
        t=0.1,
        hc=0.0,
        V=0.0,
        p=p,
        w=p,
        d=np.ones(1),
        load=0.0,
        film_center=1.0,
        film_min=1.0,
        film_min_at=(0.0, 0.0),
        p_max=1.0,
        p_max_at=(0.0, 0.0),
    )
    out = ReynoldsCavitation().finish(stepper, solved, new)
    y = out.own["p_aux"]
    assert list(np.flatnonzero(y < 0.0)) == [4, 5]  # 3 stays free, 5 stays held, 6 is released
    assert y[[0, 1, 4, 6]] == pytest.approx([1.0, 0.5, -0.2, 0.1], rel=1e-15)
    assert np.all(np.abs(y[[2, 3, 5]]) == SET_BAND)
    assert list(ReynoldsCavitation.fixed(out)) == [4, 5]
