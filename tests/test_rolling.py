"""Rolling and sliding: the two surfaces' speeds (``Motion(velocity=V, slide_roll=SRR)``).

The Reynolds equation sees only the entrainment ``V``; a viscoelastic substrate's memory
moves with the substrate's surface, ``U_s = V (1 + SRR/2)/2``; the film's Couette shear with
the sliding speed ``V SRR/2``.  Checked against the steady collocation solution of the
rolling viscoelastic line contact (femehl.reference.viscoelastic_line, no time stepping),
the relaxed elastic solution when the substrate is still, and exact identities.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import femehl
from femehl.errors import SceneError, SceneFileError
from femehl.problem.line import LineScene, _default_motion
from femehl.problem.presets import paper_sphere
from femehl.reference.line_steady import steady_line
from femehl.reference.viscoelastic_line import steady_viscoelastic_line

K, BETA, HC, L, V = 1.0, 10.0, -0.5, 2.0, 1.0  # the default LineScene's steady state


def sls(tau):
    return femehl.Viscoelastic(G0=1.0, G_inf=0.5, tau=tau)  # J0 = 1, J_inf = 2, tau_c = 2 tau


def rolling(srr, motion=None):
    return dataclasses.replace(_default_motion() if motion is None else motion, slide_roll=srr)


def test_surface_speeds():
    """SRR = 2 is the paper's sliding (the indenter's surface still), 0 pure rolling, -2 the
    substrate still; the mean of the two speeds is always V/2."""
    assert femehl.Motion(velocity=1.0).surface_speeds(0.0) == (0.0, 1.0)
    assert femehl.Motion(velocity=1.0, slide_roll=0.0).surface_speeds(0.0) == (0.5, 0.5)
    assert femehl.Motion(velocity=2.0, slide_roll=-2.0).surface_speeds(0.0) == (2.0, 0.0)
    mo = femehl.Motion(velocity=femehl.Table((0.0, 1.0), (0.0, 1.0)), slide_roll=femehl.Table((0, 1), (2, 0)))
    assert mo.surface_speeds(0.5) == pytest.approx((0.5 * 0.5 * 0.5, 0.5 * 0.5 * 1.5))
    assert 1.0 in mo.breakpoints  # a step lands where the SRR's slope jumps


def test_default_motion_describes_as_before():
    """Scenes without a slide-to-roll ratio describe (and so fingerprint run folders) as
    before it existed; SRR = 2 given explicitly is the default."""
    from femehl.output.checkpoint import describe

    assert "slide_roll" not in describe(femehl.Motion(velocity=1.0))
    assert "slide_roll" not in describe(femehl.Motion(velocity=1.0, slide_roll=2.0))
    assert "slide_roll" in describe(femehl.Motion(velocity=1.0, slide_roll=0.0))


@pytest.mark.parametrize(
    "srr, match",
    [(float("nan"), "finite"), ("fast", "SRR"), (lambda t: 1.0 / 0.0, "ZeroDivisionError")],
)
def test_bad_slide_roll(srr, match):
    with pytest.raises(SceneError, match=match):
        sc = dataclasses.replace(paper_sphere(), motion=femehl.Motion(velocity=1.0, slide_roll=srr))
        sc.domain.check(sc)


def test_scene_file_slide_roll(tmp_path):
    """``[motion] slide_roll`` (a number or a time function) and ``[si] slide_roll``."""
    import pathlib

    from femehl.problem.scenefile import load_scene_file

    root = pathlib.Path(__file__).parents[1] / "examples"
    src = (root / "cylinder_winkler.toml").read_text()
    f = tmp_path / "line.toml"
    f.write_text(src.replace("[motion.gap]", "[motion]\nslide_roll = 0.5\n[motion.gap]", 1))
    sc, _ = load_scene_file(f)
    assert sc.motion.SRR(3.0) == 0.5
    table = '[motion]\nslide_roll = {kind = "table", times = [0, 1], values = [2, 0]}\n[motion.gap]'
    f.write_text(src.replace("[motion.gap]", table, 1))
    assert load_scene_file(f)[0].motion.SRR(0.5) == pytest.approx(1.0)
    f.write_text(src.replace("[motion.gap]", '[motion]\nslide_roll = "rolling"\n[motion.gap]', 1))
    with pytest.raises(SceneFileError, match="slide_roll"):
        load_scene_file(f)
    si = (root / "sphere_si.toml").read_text()
    g = tmp_path / "si.toml"
    g.write_text(si.replace("\n[si]\n", "\n[si]\nslide_roll = 0.0\n", 1))
    sc, _ = load_scene_file(g)
    assert sc.motion.surface_speeds(5.0)[0] == pytest.approx(sc.motion.surface_speeds(5.0)[1])
    g.write_text(si.replace("\n[si]\n", "\n[si]\nslide_roll = nan\n", 1))
    with pytest.raises(SceneFileError, match="slide_roll"):
        load_scene_file(g)


@pytest.mark.parametrize("tau", [0.3, 1.0, 3.0])
def test_rolling_resistance_against_the_steady_reference(tau):
    """Pure rolling (SRR = 0) of the cylinder on the standard-linear-solid foundation, the
    automatic mode (no mesh, no dt) to t = 12 against the steady collocation solution.
    Measured (400 elements): load 6e-6 / 1.2e-6, friction (the rolling resistance) 1.3e-7 /
    1.4e-5, P_sliding 4.7e-5 / 7.4e-6 off at tau = 0.3 / 1; tolerances as for sliding
    (test_viscoelastic_steady: the 400-element mesh's spatial error, 3x the largest).
    The run's own energy budget closes: friction U_s - (shear on the cylinder) U_i =
    D_film + P_sliding, measured 2.3e-5 / 6.8e-6 / 6.9e-6 (the quadrature of its P1 fields
    and what is left of the transient), tolerance 1e-4."""
    ref = steady_viscoelastic_line(K, BETA, HC, L, V, sls(tau), slide_roll=0.0)
    r = femehl.solve(
        LineScene(k=K, beta=BETA, viscoelastic=sls(tau), motion=rolling(0.0)), t_end=12.0, tol=1e-2
    )
    assert r.load[-1] == pytest.approx(ref.load, rel=2e-5)
    assert r.friction[-1] == pytest.approx(ref.friction, rel=1e-4)
    assert r.power_sliding[-1] == pytest.approx(ref.power_sliding, rel=1e-3)
    assert r.shear_couette[-1] == 0.0  # no sliding, no Couette shear
    Ui, Us = r.scene.motion.surface_speeds(12.0)
    shear = r.shear_couette[-1] + r.shear_poiseuille[-1]
    budget = r.friction[-1] * Us - shear * Ui
    assert budget == pytest.approx(r.dissipation_film[-1] + r.power_sliding[-1], rel=1e-4)


def test_rolling_resistance_peaks_at_a_deborah_number_of_order_one():
    """The reference's rolling resistance and hysteresis against the Deborah number
    ``De = 2 U_s tau_c / a`` (the distance the material travels in a creep time over the
    contact's half width a): both vanish toward the elastic limits on either side and peak
    in between, the hysteresis at De of order one; in pure rolling the budget
    ``(friction - shear) V/2 = D_film + P_sliding`` closes (an identity of the steady
    equations, to the collocation's 1e-8)."""
    taus = np.logspace(-2.5, 3.5, 9)
    refs = [steady_viscoelastic_line(K, BETA, HC, L, V, sls(t), slide_roll=0.0) for t in taus]
    f = np.array([r.friction for r in refs])
    P = np.array([r.power_sliding for r in refs])
    a = np.sqrt(-2.0 * HC)  # the half width where the cylinder overlaps the undeformed surface
    De = 2 * (0.5 * V) * (2 * taus) / a  # U_s = V/2 in rolling, tau_c = 2 tau

    for arr in (f, P):
        i = int(np.argmax(arr))
        assert 0 < i < len(taus) - 1 and arr[i] > 1.5 * max(arr[0], arr[-1])
    assert 0.1 < De[int(np.argmax(P))] < 10.0
    for r in refs:
        assert (r.friction - r.shear_indenter) * 0.5 * V == pytest.approx(
            r.dissipation_film + r.power_sliding, rel=1e-6
        )


def test_a_still_substrate_relaxes_fully():
    """SRR = -2: the indenter's surface slides, the substrate's is still, so its memory does
    not travel and the steady state is the relaxed elastic one (G_inf = G: the elastic
    scene).  Line contact in the automatic mode: the steady shooting solution, measured
    2e-6 off (tolerance 2e-5, as above).  The 2-D disk (coarse mesh, dt = 0.02, t = 3):
    the difference from the elastic run is the memory's lag, first order in tau_c (load
    3.8e-4 and 1.5e-4 apart at tau = 0.05 and 0.02: a ratio 2.6 for 2.5); a memory moving
    with V instead of the substrate would leave the full hysteresis."""
    ve = femehl.Viscoelastic(G0=2.0, tau=0.1)
    r = femehl.solve(LineScene(k=K, beta=BETA, viscoelastic=ve, motion=rolling(-2.0)), t_end=12.0, tol=1e-2)
    assert r.load[-1] == pytest.approx(steady_line(K, BETA, HC, L, V, full=True).load, rel=2e-5)
    sc = paper_sphere()
    mo = femehl.Motion(gap=sc.motion.gap, velocity=femehl.TanhStart(t1=0.0, T=0.2), slide_roll=-2.0)
    elastic = femehl.solve(dataclasses.replace(sc, motion=mo), t_end=3.0, mesh="coarse", dt=0.02)
    gap = {}
    for tau in (0.05, 0.02):
        sc_ve = dataclasses.replace(sc, motion=mo, substrate=femehl.Viscoelastic(G0=2.0, tau=tau))
        gap[tau] = femehl.solve(sc_ve, t_end=3.0, mesh="coarse", dt=0.02).load[-1] / elastic.load[-1] - 1
    assert abs(gap[0.05]) < 1e-3 and 2.0 < gap[0.05] / gap[0.02] < 3.2


def test_entrainment_alone_sets_the_pressure():
    """On an elastic substrate the surfaces' split does not change the pressure (the
    Reynolds equation sees V only): pure rolling, sliding and SRR = -1 give the same
    fields to the bit; the Couette shear scales with the sliding speed V SRR/2, and the
    friction's other parts do not change."""
    sc = paper_sphere()
    runs = {}
    for srr in (2.0, 0.0, -1.0):
        scene = dataclasses.replace(sc, motion=rolling(srr, sc.motion))
        runs[srr] = femehl.solve(scene, t_end=2.0, mesh="coarse", dt=0.05)
    base = runs[2.0]
    for srr, r in runs.items():
        assert np.array_equal(r.final.p, base.final.p)
        assert r.shear_couette[-1] == pytest.approx(base.shear_couette[-1] * srr / 2.0, rel=1e-12)
        assert r.pressure_drag[-1] == base.pressure_drag[-1]
    assert base.shear_couette[-1] > 0  # its value against a closed form: the Martin test below


def test_friction_columns_in_every_finite_element_run(tmp_path):
    """Every finite-element run reports the friction force and its parts per step (summary.csv,
    the Result); the SI table adds the friction coefficient, friction / load."""
    import csv

    r = femehl.solve(paper_sphere(), t_end=1.5, mesh="coarse", dt=0.05, out=tmp_path / "run")
    with open(tmp_path / "run" / "summary.csv", newline="") as fh:
        head = next(csv.reader(fh))
    for c in ("friction", "shear_couette", "shear_poiseuille", "pressure_drag", "side_force"):
        assert c in head and np.all(np.isfinite(getattr(r, c)))
    assert np.all(r.shear_couette[r.V == 0.0] == 0.0) and r.shear_couette[-1] > 0  # sliding from t = 1
    dim = femehl.Dimensional(R=0.01, G=1e5, eta=0.1, V_ss=0.01, h_inf=1e-5)
    table = dim.result_table(r)
    mu = table["friction_coefficient"]
    assert np.isnan(mu[0])  # no load yet
    i = -1
    assert mu[i] == pytest.approx(r.friction[i] / r.load[i] * np.sqrt(1e-5 / 0.01), rel=1e-12)
    assert dim.unit("friction_coefficient") == "1"
    fd = femehl.solve(paper_sphere(), t_end=0.1, method="fd", dt=0.05, dr=0.1, dtheta=np.pi / 8)
    assert "friction" not in fd.extra_columns  # no pressure gradients: not reported


@pytest.mark.parametrize("srr", [0.0, 2.0])
def test_rigid_cylinder_rolling_and_sliding_against_martin(srr):
    """A nearly rigid foundation (k = 1e6: films change by p/k ~ 1e-6 of hc) under a fixed
    clearance hc = 0.1 with the Reynolds outlet condition, in the automatic mode, against
    Martin's closed form on the same finite domain (femehl.reference.rigid_cylinder): pure
    rolling and pure sliding carry the same load (the entrainment sets it), and the
    friction's parts are the closed form's: the Poiseuille shear and the pressure drag, and
    in sliding the Couette shear ``(V SRR/2)/(6 beta) int dx/d`` (zero in rolling).
    Measured: load 5.5e-6, pressure drag and Poiseuille shear 4.1e-6, Couette 2.7e-5 off
    (the element-constant film's quadrature of 1/d); tolerances 1e-4 (the load also within
    the run's own estimate, 4.4e-3)."""
    from femehl.reference.rigid_cylinder import martin_cylinder

    hc, beta = 0.1, 10.0
    ref = martin_cylinder(hc, beta, 1.0, L=2.0)
    mo = femehl.Motion(gap=hc, velocity=femehl.TanhStart(t1=0.0, T=0.1), slide_roll=srr)
    r = femehl.solve(LineScene(k=1e6, beta=beta, motion=mo, cavitation="reynolds"), t_end=2.0, tol=1e-2)
    err = r.load[-1] / ref.load - 1
    assert abs(err) < 1e-4 and abs(err) <= r.uncertainty("load", 2.0)["total"]
    assert r.pressure_drag[-1] == pytest.approx(ref.pressure_drag, rel=1e-4)
    assert r.shear_poiseuille[-1] == pytest.approx(ref.poiseuille, rel=1e-4)
    couette = (r.V[-1] * srr / 2.0) / (6.0 * beta) * ref.couette_integral
    assert r.shear_couette[-1] == pytest.approx(couette, rel=1e-4, abs=0.0)


# ---- the motion's direction against the contact's axes: an inclined ellipsoid ------------
def _ellipsoid_run(t_end=2.0, **kw):
    from femehl.problem.indenters import Ellipsoid

    sc = dataclasses.replace(paper_sphere(), indenter=Ellipsoid(0.5, 2.0, **kw), domain=femehl.Domain(3.0))
    return femehl.solve(sc, t_end=t_end, mesh="coarse", dt=0.05)


def test_inclined_ellipsoid_quarter_turns_and_input():
    """A quarter turn swaps the radii (the same gap, the same half-disk run to the bit); the
    angle 0 describes as before it existed; TOML and SI take ``angle`` in degrees."""
    from femehl.output.checkpoint import describe
    from femehl.problem.indenters import Ellipsoid, si_indenter

    assert "angle" not in describe(Ellipsoid(0.5, 2.0)) and "angle" in describe(Ellipsoid(0.5, 2.0, angle=10))
    assert Ellipsoid(0.5, 2.0, angle=90).symmetric_y and not Ellipsoid(0.5, 2.0, angle=30).symmetric_y
    assert Ellipsoid(0.5, 2.0, angle=30).curvature_radii() is None
    turned = _ellipsoid_run(angle=90.0)
    sc = dataclasses.replace(paper_sphere(), indenter=Ellipsoid(2.0, 0.5), domain=femehl.Domain(3.0))
    swapped = femehl.solve(sc, t_end=2.0, mesh="coarse", dt=0.05)
    assert turned.disc.half and np.array_equal(turned.final.p, swapped.final.p)
    dim = femehl.Dimensional(R=0.01, G=1e5, eta=0.1, V_ss=0.01, h_inf=1e-5)
    assert si_indenter("ellipsoid", {"Rx": 0.005, "Ry": 0.02, "angle": 30.0}, dim).angle == 30.0
    with pytest.raises(SceneError, match="angle"):
        Ellipsoid(0.5, 2.0, angle=float("nan"))


def test_inclined_ellipsoid_mirror_and_rotation():
    """Axes at +-30 degrees to the motion (full disk, coarse mesh, dt = 0.05): mirror images
    of each other in y while sliding (t = 2: loads 1.7e-4, central films 1.8e-3, peak
    pressures 6e-4 apart, the thinnest film on opposite sides; tolerances about 5x, the
    coarse mesh not being symmetric), and at the end of the indentation (t = 1, no motion
    yet) the pressure of the axes along x turned by 30 degrees (loads 5e-5 apart, the
    pressure at 130 points within 3.3 % of its peak: the contact edge's interpolation on
    the half and the full coarse disk; tolerance 6 %).  The force across the motion is the
    mirror's opposite."""
    plus, minus = _ellipsoid_run(angle=30.0), _ellipsoid_run(angle=-30.0)
    assert not plus.disc.half
    assert plus.load[-1] == pytest.approx(minus.load[-1], rel=1e-3)
    assert plus.film_center[-1] == pytest.approx(minus.film_center[-1], rel=1e-2)
    assert plus.p_max[-1] == pytest.approx(minus.p_max[-1], rel=3e-3)
    assert plus.final.film_min_at[1] * minus.final.film_min_at[1] < 0
    # the force across the motion: opposite (measured 0.0090 and -0.0090, 7.7e-4 apart,
    # 7.5 % of the friction); none on the half disk of the axes along the motion
    assert plus.side_force[-1] == pytest.approx(-minus.side_force[-1], rel=5e-3)
    assert plus.side_force[-1] > 0.05 * plus.friction[-1]
    along, turned = _ellipsoid_run(t_end=1.0), _ellipsoid_run(t_end=1.0, angle=30.0)
    a = np.radians(30.0)
    rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    pts = np.random.default_rng(0).uniform(-1.0, 1.0, (200, 2))
    pts = pts[np.hypot(*pts.T) < 1.2]
    p0, p30 = along.pressure_at(pts, 1.0), turned.pressure_at(pts @ rot.T, 1.0)
    assert np.abs(p0 - p30).max() < 0.06 * p0.max()
    assert turned.load[-1] == pytest.approx(along.load[-1], rel=3e-4)
    assert along.disc.half and np.all(along.side_force == 0.0)
