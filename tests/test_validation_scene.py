"""Unphysical or broken scene input is refused up front with a SceneError naming the cause.

Covers femehl.validation (the shared validators), the radius / gap-rise check of the
analytic indenters, negative imposed loads, time histories and shapes that raise or
return garbage, symmetric_y declared on an asymmetric shape, and the [run] checks of
TOML scene files (dtheta_divisions, mesh paths relative to the scene file).
"""

from __future__ import annotations

import importlib
import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import femehl.problem.scene as scene_mod
from femehl import validation
from femehl.errors import SceneError, SceneFileError
from femehl.problem.indenters import Ellipsoid, FlatPunch, HeightMap, Shape, Sphere
from femehl.problem.scene import GAP_RISE, Constant, Domain, Motion, RampHold, Scene, Table
from femehl.problem.scenefile import load_scene_file, run_options

GAP = Motion(gap=0.1)  # a positive clearance: no contact check, only the shape checks
L = 2.0
R_LO, R_HI = L * L / (2 * GAP_RISE[1]), L * L / (2 * GAP_RISE[0])  # 2e-6, 2e6


# ---- 1. the validators live in femehl.validation; no import cycle --------------------------
def test_validators_are_shared_and_reexported():
    assert scene_mod.check_finite is validation.check_finite
    assert scene_mod.check_positive is validation.check_positive


def test_indenters_imports_without_scene():
    """femehl.problem.indenters does not import femehl.problem.scene (a former cycle), only
    femehl.validation."""
    src = importlib.util.find_spec("femehl.problem.indenters").origin
    with open(src, encoding="utf-8") as f:
        text = f.read()
    imports = [line for line in text.splitlines() if line.lstrip().startswith(("import ", "from "))]
    assert not any("femehl.problem.scene" in line for line in imports)
    assert any(line.startswith("from femehl.validation import") for line in imports)
    code = "import femehl.problem.indenters as i, femehl.validation as v; "
    code += "assert i.check_positive is v.check_positive"
    subprocess.run([sys.executable, "-c", code], check=True)


@pytest.mark.parametrize(
    "value,match",
    [
        ("1", "must be a real number"),
        (True, "must be a real number"),
        (1 + 2j, "must be a real number"),
        (math.nan, "must be finite"),
        (math.inf, "must be finite"),
        (0.0, "must be > 0"),
        (-1, "must be > 0"),
    ],
)
def test_check_positive_names_value_and_hint(value, match):
    with pytest.raises(SceneError, match=match + ".*Use 3"):
        validation.check_positive("x", value, "Use 3.")


@pytest.mark.parametrize(
    "value,match",
    [
        (2.0, "must be an integer"),
        (True, "must be an integer"),
        ("3", "must be an integer"),
        (1, "integer >= 2"),
    ],
)
def test_check_int(value, match):
    with pytest.raises(SceneError, match=match):
        validation.check_int("n", value, minimum=2)
    assert validation.check_int("n", np.int64(3), minimum=2) == 3


def test_check_shape_values_never_mutates_and_refuses_garbage():
    a = np.arange(4.0)
    out = validation.check_shape_values("f", a, (4,))
    out[0] = 99.0
    assert a[0] == 0.0
    with pytest.raises(SceneError, match="complex values"):
        validation.check_shape_values("f", a + 1j, (4,))
    with pytest.raises(SceneError, match=r"returned shape \(3,\).*one value per point"):
        validation.check_shape_values("f", a[:3], (4,))
    with pytest.raises(SceneError, match="must return real numbers"):
        validation.check_shape_values("f", ["a", "b", "c", "d"], (4,))
    assert validation.check_shape_values("f", 2.0, (2, 2)).shape == (2, 2)


# ---- 2a. indenter radii: the gap must rise by 1e-6 .. 1e6 across the domain ----------------
@pytest.mark.parametrize(
    "indenter,match",
    [
        (Sphere(1e-300), r"Sphere\(R=1e-300\) is too sharp.*rises to 2e\+300.*2e-06 <= R <= 2e\+06"),
        (Sphere(1e300), r"Sphere\(R=1e\+300\) is flat on the domain.*holds no contact edge.*R <= 2e\+06"),
        (Sphere(1e-7), r"too sharp.*contact is a dot"),
        (Sphere(1e7), r"is flat on the domain"),
        (Ellipsoid(1.0, 1e-300), r"Ellipsoid.*too sharp.*min\(Rx, Ry\)"),
        (Ellipsoid(1e300, 1e300), r"Ellipsoid.*flat on the domain"),
        (FlatPunch(3.0, 0.5), r"FlatPunch.*flat on the domain.*flat face \(a = 3\) covers the whole domain"),
        (FlatPunch(2.0, 0.5), r"flat face \(a = 2\) covers"),
        (FlatPunch(0.5, 1e-300), r"FlatPunch.*too sharp.*edge_radius"),
        (FlatPunch(0.5, 1e300), r"FlatPunch.*flat on the domain.*edge_radius <="),
    ],
)
def test_indenter_radius_out_of_range_is_refused(indenter, match):
    with pytest.raises(SceneError, match=match):
        Scene(indenter=indenter, motion=GAP, domain=Domain(L))


@settings(max_examples=40, deadline=None)
@given(log_r=st.floats(math.log10(R_LO) + 0.01, math.log10(R_HI) - 0.01))
def test_any_radius_in_range_builds_a_scene_with_a_finite_gap(log_r):
    R = 10.0**log_r
    sc = Scene(indenter=Sphere(R), motion=GAP, domain=Domain(L))
    g = np.linspace(-L, L, 41)
    X, Y = np.meshgrid(g, g)
    inside = X**2 + Y**2 <= L * L
    s = sc.indenter.gap(X[inside], Y[inside])
    assert np.all(np.isfinite(s)) and np.all(s >= 0.0)
    assert np.all(np.isfinite(sc.motion.hc(0.0) + s))


@settings(max_examples=60, deadline=None)
@given(
    R=st.one_of(
        st.floats(min_value=5e-324, max_value=R_LO * 0.99),
        st.floats(min_value=R_HI * 1.01, max_value=1.7e308),
    )
)
def test_any_radius_outside_the_range_is_refused_with_scene_error(R):
    with pytest.raises(SceneError, match=r"Sphere\(R=.*(too sharp|is flat) .*domain.*R <= 2e\+06"):
        Scene(indenter=Sphere(R), motion=GAP, domain=Domain(L))


@settings(max_examples=40, deadline=None)
@given(
    R=st.one_of(
        st.floats(allow_nan=True, allow_infinity=True),
        st.integers(-10, 0),
        st.text(max_size=3),
        st.none(),
        st.complex_numbers(),
    )
)
def test_any_radius_input_gives_scene_error_or_a_valid_scene(R):
    """Never another exception: a Sphere radius is either accepted or refused as SceneError."""
    try:
        sc = Scene(indenter=Sphere(R), motion=GAP, domain=Domain(L))
    except SceneError:
        return
    assert R_LO <= sc.indenter.R <= R_HI * (1 + 1e-12)


def test_heightmap_and_shape_may_be_flat_plates():
    """The rise check is about analytic radii: a flat user shape is taken as given."""
    Scene(indenter=Shape(lambda x, y: 0.0 * x), motion=GAP)
    g = np.linspace(-2.0, 2.0, 3)
    Scene(indenter=HeightMap(g, g, np.zeros((3, 3))), motion=GAP)


# ---- 2b. negative imposed loads ----------------------------------------------------------
@pytest.mark.parametrize(
    "load,t",
    [
        (-1.0, "0"),
        (Table([0.0, 2.0], [0.1, -0.1]), "1.01"),
        (Table([0.0, 3.0, 4.0], [0.0, 0.0, -0.5]), r"3\.01"),
        (Table([0.0, 50.0], [0.0, -1.0]), r"0\.05"),  # sampled past t = 10 (a table time)
        (lambda t: 0.2 - 0.1 * t, r"2\.01"),
    ],
)
def test_negative_load_is_refused_naming_time(load, t):
    with pytest.raises(
        SceneError,
        match=rf"imposed load F\(t={t}\) = -[0-9.e-]+ is negative: "
        r"the lubricated model cannot pull",
    ):
        Scene(motion=Motion(gap=0.1, load=load))


def test_negative_load_at_run_time_is_refused():
    m = Motion(gap=0.1, load=lambda t: 0.1 if t < 20 else -1.0)
    sc = Scene(motion=m, domain=Domain(2.0))  # t = 20 is not sampled
    assert sc.motion.F(1.0) == 0.1
    with pytest.raises(SceneError, match=r"F\(t=25\) = -1 is negative"):
        sc.motion.F(25.0)


def test_zero_load_is_allowed():
    Scene(motion=Motion(gap=0.1, load=0.0))
    Scene(motion=Motion(gap=0.1, load=Table([0.0, 1.0], [0.0, 0.3])))


# ---- 2c. histories and shapes that raise or return garbage ---------------------------------
def _boom(t):
    raise ZeroDivisionError("bad")


@pytest.mark.parametrize(
    "kw,history",
    [
        ({"gap": _boom}, r"the gap history hc\(t\) raised ZeroDivisionError at t = 0"),
        ({"gap": 0.1, "load": _boom}, r"the load history F\(t\) raised ZeroDivisionError at t = 0"),
        ({"gap": 0.1, "velocity": _boom}, r"the velocity history V\(t\) raised ZeroDivisionError at t = 0"),
    ],
)
def test_history_that_raises_is_refused_naming_history(kw, history):
    with pytest.raises(SceneError, match=history + r" \(bad\): fix the function"):
        Scene(motion=Motion(**kw))


@pytest.mark.parametrize(
    "method,name,symbol", [("hc", "gap", "hc"), ("V", "velocity", "V"), ("F", "load", "F")]
)
def test_history_that_raises_later_names_history_and_time(method, name, symbol):
    def f(t):
        if t < 1.0:
            return 0.1
        raise IndexError("list index out of range")

    m = Motion(**{"gap": 0.1, name: f})
    assert getattr(m, method)(0.5) == 0.1
    with pytest.raises(SceneError, match=rf"history {symbol}\(t\) raised IndexError at t = 1\.5"):
        getattr(m, method)(1.5)


@pytest.mark.parametrize(
    "value,match",
    [
        (1j, "must be a real number"),
        (math.nan, "must be finite"),
        ("0.1", "must be a real number"),
        (np.array([0.1, 0.2]), "must be a real number"),
    ],
)
def test_history_returning_garbage(value, match):
    m = Motion(gap=lambda t: value)
    with pytest.raises(SceneError, match=r"hc\(t=0\) " + match):
        m.hc(0.0)


@pytest.mark.parametrize(
    "func,match",
    [
        (lambda x, y: np.sqrt(x * x + y * y - 0j), "returned complex values"),
        (lambda x, y: np.where(x > 1.5, np.nan, x * x), r"not finite \(NaN or inf\)"),
        (lambda x, y: np.where(x > 1.5, np.inf, x * x), r"not finite \(NaN or inf\)"),
        (lambda x, y: (x * x)[:2], "returned shape"),
        (lambda x, y: 1 / (x - x), r"not finite"),
        (lambda x, y: {}["k"], "raised KeyError"),
    ],
)
def test_bad_shape_is_refused_naming_the_shape(func, match):
    with pytest.raises(SceneError, match=r"Shape 'ripple'.*" + match):
        Scene(indenter=Shape(func, name="ripple"), motion=GAP)


def test_shape_input_arrays_never_mutated():
    seen = []

    def f(x, y):
        x += 1.0  # a careless user function
        seen.append(x)
        return (x - 1.0) ** 2 + y**2

    sh = Shape(f)
    x = np.zeros(3)
    sh.gap(x, x)
    assert np.all(x == 0.0)


# ---- 2d. symmetric_y declared on an asymmetric shape --------------------------------------
def test_symmetric_y_declared_on_asymmetric_shape_is_refused_at_construction():
    with pytest.raises(SceneError, match=r"declares symmetric_y=True.*symmetric_y=False"):
        Shape(lambda x, y: 0.5 * (x * x + y * y) + 0.1 * np.maximum(y, 0.0) ** 2, symmetric_y=True)


def test_symmetric_y_checked_on_the_whole_domain():
    """Asymmetric only beyond |y| = 1.1 (outside Shape's own sample grid): the scene finds it."""
    sh = Shape(
        lambda x, y: 0.5 * (x * x + y * y) + 0.1 * np.maximum(y - 1.1, 0.0) ** 2,
        symmetric_y=True,
        name="late",
    )
    with pytest.raises(
        SceneError,
        match=r"Shape 'late' declares symmetric_y=True.*not symmetric in y "
        r"on the domain r <= 2",
    ):
        Scene(indenter=sh, motion=GAP)
    Scene(indenter=Shape(sh.func, symmetric_y=False), motion=GAP)


def test_heightmap_declared_symmetric_but_not():
    g = np.linspace(-2.0, 2.0, 21)
    z = 0.5 * (g[:, None] ** 2 + g[None, :] ** 2) + 0.2 * np.maximum(g[None, :], 0.0)
    with pytest.raises(SceneError, match="HeightMap.*declares symmetric_y=True"):
        Scene(indenter=HeightMap(g, g, z, symmetric_y=True), motion=GAP)
    Scene(indenter=HeightMap(g, g, z), motion=GAP)  # detected: not symmetric


@pytest.mark.parametrize(
    "ind",
    [
        Sphere(1.0),
        Ellipsoid(0.5, 2.0),
        FlatPunch(0.5, 0.5),
        Shape(lambda x, y: np.cosh(y) - 1 + x * x, symmetric_y=True),
    ],
)
def test_truly_symmetric_shapes_pass(ind):
    Scene(indenter=ind, motion=GAP)


# ---- 4. scene files: [run] dtheta_divisions and mesh ---------------------------------------
def _write(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(text, encoding="utf-8")
    return p


@pytest.mark.parametrize(
    "value,match",
    [
        ("0", "must be an integer >= 2"),
        ("-3", "must be an integer >= 2"),
        ("1", "must be an integer >= 2"),
        ("2.5", "must be an integer"),
        ("30.0", "must be an integer"),
        ('"30"', "must be an integer"),
        ("true", "must be an integer"),
    ],
)
def test_dtheta_divisions_refused_naming_the_key(tmp_path, value, match):
    p = _write(tmp_path, f"[run]\ndtheta_divisions = {value}\n")
    with pytest.raises(SceneFileError, match=r"s\.toml: \[run\] dtheta_divisions " + match):
        load_scene_file(p)


def test_dtheta_divisions_accepted(tmp_path):
    _, run = load_scene_file(_write(tmp_path, "[run]\ndtheta_divisions = 30\n"))
    assert run_options(run)["dtheta"] == pytest.approx(math.pi / 30)


def test_mesh_path_relative_to_the_scene_file(tmp_path):
    p = _write(tmp_path, '[run]\nmesh = "meshes/my.msh"\n', name="sub/s.toml")
    _, run = load_scene_file(p)
    assert run["mesh"] == str(tmp_path / "sub" / "meshes" / "my.msh")


def test_mesh_ladder_name_and_absolute_path_unchanged(tmp_path):
    _, run = load_scene_file(_write(tmp_path, '[run]\nmesh = "fine"\n'))
    assert run["mesh"] == "fine"
    absolute = str(tmp_path / "abs.msh")
    _, run = load_scene_file(_write(tmp_path, f'[run]\nmesh = "{absolute}"\n'))
    assert run["mesh"] == absolute


@pytest.mark.parametrize("value", ["3", '""', "[1, 2]"])
def test_mesh_not_a_string_is_refused(tmp_path, value):
    with pytest.raises(SceneFileError, match=r"\[run\] mesh must be a ladder name"):
        load_scene_file(_write(tmp_path, f"[run]\nmesh = {value}\n"))


def test_scene_file_radius_and_negative_load(tmp_path):
    with pytest.raises(SceneFileError, match=r"s\.toml: .*Sphere\(R=1e-300\) is too sharp"):
        load_scene_file(
            _write(
                tmp_path,
                '[indenter]\nkind = "sphere"\nR = 1e-300\n[motion.gap]\nkind = "constant"\nvalue = 0.1\n',
            )
        )
    with pytest.raises(SceneFileError, match=r"s\.toml: .*F\(t=0\) = -2 is negative"):
        load_scene_file(
            _write(tmp_path, '[motion]\nload = -2.0\n[motion.gap]\nkind = "constant"\nvalue = 0.1\n')
        )


def test_motion_inputs_not_mutated():
    t = Table([0.0, 1.0], [0.1, 0.2])
    m = Motion(gap=t, load=Constant(0.1))
    Scene(motion=m)
    assert m.gap is t and t.values == (0.1, 0.2)
    assert isinstance(Motion(gap=RampHold()).gap, RampHold)
