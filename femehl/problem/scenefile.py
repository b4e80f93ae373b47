"""TOML scene files: the CLI's way to state a scene (and how to run it).

:func:`load_scene_file` reads one into a scene and its run options.  Each table names a
*kind* looked up in a registry, never an if/elif chain: add a shape, substrate or time
function by adding it to the registry.  The format, the line-contact and ``[si]`` tables:
docs/scene.md ("Scene files (TOML)"); a commented example is ``examples/paper_sphere.toml``.
Every problem raises :class:`~femehl.errors.SceneFileError` naming the file and the key
to fix.
"""

from __future__ import annotations

import dataclasses
import inspect
import math
import pathlib

from femehl.errors import SceneError, SceneFileError
from femehl.problem.indenters import INDENTERS, si_indenter
from femehl.problem.scene import (
    Constant,
    Dimensional,
    Domain,
    Fluid,
    Motion,
    RampHold,
    Scene,
    Table,
    TanhStart,
)
from femehl.validation import check_finite, check_int, check_positive

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    import tomli as tomllib

__all__ = [
    "INDENTERS",
    "LINE_RUN_KEYS",
    "RUN_KEYS",
    "SUBSTRATES",
    "TIME_FUNCTIONS",
    "load_scene_file",
    "scene_from_mapping",
]

from femehl.elastic import SUBSTRATES  # noqa: E402  (kind -> class, filled by the substrates)

TIME_FUNCTIONS = {"constant": Constant, "table": Table, "ramp_hold": RampHold, "tanh": TanhStart}
RUN_KEYS = {
    "method",
    "scheme",
    "t_end",
    "dt",
    "store_every",
    "mesh",
    "dr",
    "dtheta_divisions",
    "linear_solver",
    "tol",
    "step_tol",
    "operator",
    "operator_tol",
    "max_wall",
}
#: [run] keys of a line-contact scene ([indenter] kind = "cylinder")
LINE_RUN_KEYS = {
    "method",
    "scheme",
    "t_end",
    "dt",
    "store_every",
    "n_elements",
    "grading",
    "tol",
    "step_tol",
    "max_wall",
}


def _build(registry, table, where, path):
    if not isinstance(table, dict):
        raise SceneFileError(f"{path}: [{where}] must be a table, got {table!r}.")
    table = dict(table)
    kind = table.pop("kind", None)
    if not isinstance(kind, str) or kind not in registry:
        raise SceneFileError(
            f"{path}: [{where}] kind = {kind!r} is not known; use one of {sorted(registry)}."
        )
    cls = registry[kind]
    if "file" in table and hasattr(cls, "from_file"):
        # data read from a file next to the scene file (e.g. a height map .npz)
        file = pathlib.Path(str(table.pop("file")))
        if not file.is_absolute():
            file = pathlib.Path(path).parent / file
        allowed = set(inspect.signature(cls.from_file).parameters) - {"path"}
        extra = set(table) - allowed
        if extra:
            raise SceneFileError(
                f"{path}: [{where}] kind = {kind!r} with file = ... does not take "
                f"{sorted(extra)}; it takes {sorted(allowed | {'file'})}."
            )
        try:
            return cls.from_file(file, **table)
        except (SceneError, TypeError) as exc:
            raise SceneFileError(f"{path}: [{where}]: {exc}") from None
    allowed = set(inspect.signature(cls).parameters)
    extra = set(table) - allowed
    if extra:
        raise SceneFileError(
            f"{path}: [{where}] kind = {kind!r} does not take {sorted(extra)}; it takes {sorted(allowed)}."
        )
    for key, value in table.items():  # a nested table of the same registry (a relaxing solid's)
        if isinstance(value, dict) and "kind" in value:
            table[key] = _build(registry, value, f"{where}.{key}", path)
    try:
        return cls(**table)
    except SceneError as exc:
        raise SceneFileError(f"{path}: [{where}]: {exc}") from None
    except TypeError as exc:
        raise SceneFileError(f"{path}: [{where}]: {exc}") from None


def _time_function(value, where, path):
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        try:
            return Constant(value)
        except SceneError as exc:
            raise SceneFileError(f"{path}: [{where}]: {exc}") from None
    return _build(TIME_FUNCTIONS, value, where, path)


def load_scene_file(path) -> tuple[Scene, dict]:
    """Read a TOML scene file; return ``(scene, run_options)``.

    A file whose ``[indenter]`` has ``kind = "cylinder"`` states line contact:
    the scene is then a :class:`femehl.problem.line.LineScene` and the run options
    those of :func:`femehl.api.solve_line` (see :data:`LINE_RUN_KEYS`).

    When the file states the scene in SI units (an ``[si]`` table), the run
    options also hold the :class:`~femehl.problem.scene.Dimensional` under the key
    ``"_dimensional"`` (pop it before passing the options to a solver; the CLI
    uses it to write ``summary_si.csv``).

    Parameters
    ----------
    path : str or pathlib.Path

    Raises
    ------
    SceneFileError
        Unreadable file, TOML syntax error, unknown table/kind/key, invalid value.
    """
    path = pathlib.Path(path)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SceneFileError(f"scene file {str(path)!r} does not exist: check the path.") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneFileError(f"cannot read scene file {str(path)!r}: {exc}.") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneFileError(f"{path}: not valid TOML ({exc}); see examples/paper_sphere.toml.") from None
    return scene_from_mapping(raw, path)


def substrate_from_mapping(table: dict, path="[substrate]"):
    """A substrate from a scene-file table such as ``{"kind": "winkler", "k": 2.0}``."""
    return _build(SUBSTRATES, table, "substrate", path)


def scene_from_mapping(raw: dict, path) -> tuple:
    """``(scene, run_options)`` of a scene file's content already read (a dict of tables).

    ``path`` names the file in messages and anchors its relative paths (height maps,
    mesh files); see :func:`load_scene_file`.  ``raw`` is not modified.
    """
    import copy

    path = pathlib.Path(path)
    raw = copy.deepcopy(raw)
    known = {"indenter", "substrate", "fluid", "motion", "domain", "roughness", "run", "si"}
    unknown = set(raw) - known
    if unknown:
        raise SceneFileError(f"{path}: unknown table(s) {sorted(unknown)}; known: {sorted(known)}.")
    run = raw.get("run", {})
    if not isinstance(run, dict):
        raise SceneFileError(f"{path}: [run] must be a table.")
    run = dict(run)
    if _is_line(raw):
        try:
            return _line_scene(raw, path), _line_run(run, path)
        except SceneFileError:
            raise
        except SceneError as exc:
            raise SceneFileError(f"{path}: {exc}") from None
    extra = set(run) - RUN_KEYS
    if extra:
        raise SceneFileError(f"{path}: [run] does not take {sorted(extra)}; it takes {sorted(RUN_KEYS)}.")
    _check_run(run, path)
    try:
        if "si" in raw:
            if "roughness" in raw:
                raise SceneFileError(
                    f"{path}: [roughness] is stated in normalized units (sigma over h_inf, stiffness "
                    "over p0); a [si] scene takes its roughness in SI: [si] roughness_rms [m], "
                    "asperity_density [1/m2], asperity_radius [m] (optional summit_rms [m], "
                    "boundary_friction)."
                )
            scene, dim = _si_scene(raw, path)
            run["_dimensional"] = dim
        else:
            scene = _normalized_scene(raw, path)
    except SceneFileError:
        raise
    except SceneError as exc:
        raise SceneFileError(f"{path}: {exc}") from None
    return scene, run


def _roughness(raw, path):
    """[roughness] sigma, stiffness and friction (femehl.Roughness), or None."""
    from femehl.problem.roughness import Roughness

    table = raw.get("roughness")
    if table is None:
        return None
    keys = {"sigma", "stiffness", "friction", "aspect"}
    if not isinstance(table, dict) or set(table) - keys or not {"sigma", "stiffness"} <= set(table):
        raise SceneFileError(
            f"{path}: [roughness] takes sigma and stiffness (and friction with aspect), got "
            f"{sorted(table) if isinstance(table, dict) else table!r}."
        )
    return Roughness(**table)


def _check_run(run: dict, path: pathlib.Path) -> None:
    """Check the [run] keys femehl can check without a solver; resolve ``mesh`` (in place).

    ``dtheta_divisions`` must be an integer >= 2.  A ``mesh`` that is neither a ladder
    name nor an absolute path is a file relative to the scene file's folder (like a
    height map's ``file``).
    """
    if "dtheta_divisions" in run:
        check_int(
            f"{path}: [run] dtheta_divisions",
            run["dtheta_divisions"],
            minimum=2,
            hint="It is the number of angular divisions of the half turn (dtheta = pi/n), "
            "e.g. dtheta_divisions = 30.",
            error=SceneFileError,
        )
    if "mesh" in run:
        mesh = run["mesh"]
        if not isinstance(mesh, str) or not mesh.strip():
            raise SceneFileError(
                f"{path}: [run] mesh must be a ladder name (coarse, medium, fine, "
                f"xfine) or the path of a mesh file, got {mesh!r}."
            )
        from femehl.discretize.mesh import LADDER  # lazy: only scene files that name a mesh need the FE code

        if mesh not in LADDER and not pathlib.Path(mesh).is_absolute():
            run["mesh"] = str(pathlib.Path(path).parent / mesh)


def _si_scene(raw, path):
    """The paper's experiment in SI units; returns (scene, Dimensional)."""
    clash = {"substrate", "fluid", "motion", "domain"} & set(raw)
    if clash:
        raise SceneFileError(
            f"{path}: [si] replaces {sorted(clash)}; give one or the other "
            "(only [indenter] may accompany [si], in metres; a cavitation condition is "
            '[si] cavitation = "reynolds", the slide-to-roll ratio [si] slide_roll).'
        )
    si = raw["si"]
    if not isinstance(si, dict):
        raise SceneFileError(f"{path}: [si] must be a table.")
    si = dict(si)
    visco = {"G0", "tau", "G_inf"}  # a standard linear solid: unrelaxed modulus, relaxation time
    free = {"mass", "force", "hc_dot0", "sliding"}  # a free indenter: kg, N, m/s; sliding on/off
    free |= {"cavitation", "slide_roll"}  # [fluid] cavitation; the slide-to-roll ratio (2: sliding)
    rough = {"roughness_rms", "asperity_density", "asperity_radius", "summit_rms", "boundary_friction"}
    optional = {"nu", "t1", "T", "L", "load", "alpha", "roelands_Z", "layer_thickness"} | visco | free | rough
    keys = {"R", "G", "eta", "V_ss", "h_inf", "h0"} | optional
    extra = set(si) - keys
    missing = (keys - optional) - set(si)
    if extra or missing:
        raise SceneFileError(
            f"{path}: [si] needs {sorted(keys - optional)} "
            f"(optional {sorted(optional)}); missing {sorted(missing)}, unknown {sorted(extra)}."
        )
    try:
        dim = Dimensional(**{k: si[k] for k in ("R", "G", "eta", "V_ss", "h_inf")}, nu=si.get("nu", 0.5))
        scene = dim.scene(si["h0"], si.get("t1"), si.get("T"), si.get("L", 2.0))
        changes = {}
        if "indenter" in raw:
            ind = raw["indenter"]
            if not isinstance(ind, dict):
                raise SceneFileError(f"{path}: [indenter] must be a table.")
            ind = dict(ind)
            kind = ind.pop("kind", None)
            changes["indenter"] = si_indenter(kind, ind, dim)
        if "layer_thickness" in si:  # an elastic layer on a rigid base, thickness in metres
            from femehl.elastic import Layer

            h = check_finite("[si] layer_thickness [m]", si["layer_thickness"])
            if h <= 0.0:
                raise SceneError(
                    f"[si] layer_thickness must be > 0 (metres), got {h:g}; leave it out for a half space."
                )
            changes["substrate"] = Layer(h / dim.length, nu=dim.nu)
        if "load" in si:  # applied over the indentation ramp's time t1, then held (not at once: the
            # pressure and the film at the rim jump at an impulsive start, which no step resolves)
            F = check_finite("[si] load [N]", si["load"]) / dim.force
            t1 = scene.motion.gap.breakpoints[0]
            changes["motion"] = dataclasses.replace(
                scene.motion, gap=Constant(scene.motion.hc(0.0)), load=RampHold(0.0, F, t1)
            )
        if "alpha" in si or "roelands_Z" in si:  # pressure-viscosity: Barus [1/Pa], or Roelands
            from femehl.problem.viscosity import Barus, Roelands

            if "roelands_Z" in si:
                if "alpha" in si:
                    raise SceneFileError(
                        f"{path}: [si] gives alpha (Barus) and roelands_Z (Roelands): give one; "
                        "Roelands takes its slope from eta and Z."
                    )
                model = Roelands.from_si(si["eta"], dim, Z=si["roelands_Z"])
            else:
                model = Barus.from_si(si["alpha"], dim)
            changes["fluid"] = dataclasses.replace(scene.fluid, viscosity=model)
        if "sliding" in si and not isinstance(si["sliding"], bool):
            raise SceneFileError(f"{path}: [si] sliding must be true or false, got {si['sliding']!r}.")
        if free & set(si) - {"sliding", "cavitation", "slide_roll"}:  # a free indenter (Newton's law), in SI
            if "mass" not in si or "load" in si:
                raise SceneFileError(
                    f"{path}: [si] a free indenter needs mass [kg] (with optional force [N] and "
                    "hc_dot0 [m/s], the initial dhc/dt, < 0 toward the substrate), and no load."
                )
            m = check_positive("[si] mass [kg]", si["mass"], "Give the indenter's mass in kg.")
            changes["motion"] = dataclasses.replace(
                scene.motion,
                gap=Constant(check_positive("[si] h0 [m]", si["h0"]) / dim.height),
                mass=m / dim.mass,
                force=check_finite("[si] force [N]", si.get("force", 0.0)) / dim.force,
                hc_dot0=check_finite("[si] hc_dot0 [m/s]", si.get("hc_dot0", 0.0)) / dim.approach_speed,
            )
        if rough & set(si):  # a rough surface: Greenwood-Tripp from the surfaces' statistics
            need = {"roughness_rms", "asperity_density", "asperity_radius"}
            if need - set(si):
                raise SceneFileError(
                    f"{path}: [si] a rough surface needs {sorted(need)} (optional summit_rms [m], "
                    f"boundary_friction); missing {sorted(need - set(si))}."
                )
            changes["roughness"] = dim.roughness(
                si["roughness_rms"],
                si["asperity_density"],
                si["asperity_radius"],
                si.get("summit_rms"),
                si.get("boundary_friction", 0.0),
            )
        if "cavitation" in si:
            fluid = changes.get("fluid", scene.fluid)
            changes["fluid"] = dataclasses.replace(fluid, cavitation=si["cavitation"])
        if si.get("sliding", True) is False:  # no sliding: the indenter only approaches
            mo = changes.get("motion", scene.motion)
            changes["motion"] = dataclasses.replace(mo, velocity=Constant(0.0))
        if "slide_roll" in si:  # dimensionless: the same number in SI
            srr = check_finite("[si] slide_roll", si["slide_roll"], "2 is pure sliding, 0 pure rolling.")
            mo = changes.get("motion", scene.motion)
            changes["motion"] = dataclasses.replace(mo, slide_roll=Constant(srr))
        if visco & set(si):
            if not {"G0", "tau"} <= set(si):
                raise SceneFileError(
                    f"{path}: [si] a viscoelastic substrate needs G0 [Pa] (unrelaxed modulus) and "
                    "tau [s] (relaxation time); G_inf [Pa] is optional (default: G)."
                )
            from femehl.elastic import Viscoelastic

            changes["substrate"] = Viscoelastic.from_si(
                si["G0"], si["tau"], dim, G_inf=si.get("G_inf"), elastic=scene.substrate
            )
        if changes:
            scene = dataclasses.replace(scene, **changes)
    except SceneFileError:
        raise
    except SceneError as exc:
        raise SceneFileError(f"{path}: [si]: {exc}") from None
    return scene, dim


def _normalized_scene(raw, path):
    indenter = _build(INDENTERS, raw.get("indenter", {"kind": "sphere"}), "indenter", path)
    substrate = _build(SUBSTRATES, raw.get("substrate", {"kind": "halfspace"}), "substrate", path)
    fluid = _fluid(raw, path)
    motion = _motion(raw, path)
    domain = raw.get("domain", {})
    if not isinstance(domain, dict) or set(domain) - {"L"}:
        raise SceneFileError(f"{path}: [domain] takes only L.")
    return Scene(
        indenter=indenter,
        substrate=substrate,
        fluid=Fluid(**fluid),
        motion=motion,
        domain=Domain(**domain),
        roughness=_roughness(raw, path),
    )


def _fluid(raw, path) -> dict:
    """[fluid] beta and [fluid.viscosity] (kind = "barus" | "roelands", see femehl.problem.viscosity)."""
    from femehl.problem.viscosity import VISCOSITY_MODELS

    fluid = raw.get("fluid", {})
    if not isinstance(fluid, dict) or set(fluid) - {"beta", "viscosity", "cavitation"}:
        raise SceneFileError(f"{path}: [fluid] takes beta, cavitation and a [fluid.viscosity] table only.")
    fluid = dict(fluid)
    if "viscosity" in fluid:
        fluid["viscosity"] = _build(VISCOSITY_MODELS, fluid["viscosity"], "fluid.viscosity", path)
    return fluid


def _motion(raw, path) -> Motion:
    """[motion.gap], [motion.velocity], [motion.slide_roll], [motion.load] -> Motion (shared by
    2-D and line scenes)."""
    motion = raw.get("motion", {})
    if not isinstance(motion, dict):
        raise SceneFileError(f"{path}: [motion] must be a table.")
    motion = dict(motion)
    extra = set(motion) - {"gap", "velocity", "slide_roll", "load", "mass", "force", "hc_dot0"}
    if extra:
        raise SceneFileError(
            f"{path}: [motion] takes gap, velocity, slide_roll, load, and for a free indenter mass, "
            f"force and hc_dot0, not {sorted(extra)}."
        )
    gap = _time_function(motion.get("gap", {"kind": "ramp_hold"}), "motion.gap", path)
    vel = _time_function(motion.get("velocity", 0.0), "motion.velocity", path)
    load = None
    if "load" in motion:
        load = _time_function(motion["load"], "motion.load", path)
    free = {}
    if "slide_roll" in motion:
        free["slide_roll"] = _time_function(motion["slide_roll"], "motion.slide_roll", path)
    if "force" in motion:
        free["force"] = _time_function(motion["force"], "motion.force", path)
    free.update({k: motion[k] for k in ("mass", "hc_dot0") if k in motion})
    try:
        return Motion(gap=gap, velocity=vel, load=load, **free)
    except SceneError as exc:
        raise SceneFileError(f"{path}: [motion]: {exc}") from None


def _is_line(raw) -> bool:
    ind = raw.get("indenter")
    return isinstance(ind, dict) and ind.get("kind") == "cylinder"


def _line_scene(raw, path):
    """[indenter] kind = "cylinder": a :class:`femehl.problem.line.LineScene`."""
    from femehl.problem.line import LineScene

    if "si" in raw:
        raise SceneFileError(
            f"{path}: [si] states the sphere experiment; line contact "
            '([indenter] kind = "cylinder") is stated in normalized units: '
            "replace [si] by [substrate], [fluid], [motion] and [domain]."
        )
    ind = dict(raw["indenter"])
    ind.pop("kind")
    extra = set(ind) - {"R"}
    if extra:
        raise SceneFileError(
            f"{path}: [indenter] kind = 'cylinder' does not take {sorted(extra)}; it takes only R (= 1)."
        )
    if "R" in ind:
        R = ind["R"]
        if isinstance(R, bool) or not isinstance(R, (int, float)) or R != 1:
            raise SceneFileError(
                f"{path}: [indenter] kind = 'cylinder' has R = {R!r}, but line contact is "
                "normalized by the cylinder's radius (gap x^2/2): R must be 1.0 (or left out). "
                "Rescale the other parameters instead."
            )
    sub = raw.get("substrate")
    visco = None
    if isinstance(sub, dict) and sub.get("kind") == "viscoelastic":  # relaxing its Winkler foundation
        visco = _build(SUBSTRATES, sub, "substrate", path)
        if type(visco.elastic).__name__ != "Winkler":
            raise SceneFileError(
                f"{path}: [substrate] kind = 'viscoelastic' for line contact relaxes a Winkler "
                'foundation: give elastic = {kind = "winkler", k = ...}.'
            )
        sub = {"kind": "winkler", "k": visco.elastic.k}
    if not isinstance(sub, dict) or sub.get("kind") != "winkler":
        got = sub.get("kind") if isinstance(sub, dict) else sub
        raise SceneFileError(
            f"{path}: [substrate] kind = {got!r}: line contact needs a Winkler foundation "
            "([indenter] kind = 'cylinder'); give [substrate] kind = \"winkler\" with k = ..., "
            'or use a 3-D indenter (e.g. kind = "sphere") for other substrates.'
        )
    winkler = _build(SUBSTRATES, sub, "substrate", path)
    fluid = _fluid(raw, path)
    motion = _motion(raw, path)
    domain = raw.get("domain", {})
    if not isinstance(domain, dict) or set(domain) - {"L"}:
        raise SceneFileError(f"{path}: [domain] takes only L.")
    kw = {"k": winkler.k, "motion": motion, **({"viscoelastic": visco} if visco is not None else {})}
    kw.update({k: fluid[k] for k in ("beta", "viscosity", "cavitation") if k in fluid})
    kw["roughness"] = _roughness(raw, path)
    if "L" in domain:
        kw["L"] = domain["L"]
    try:
        return LineScene(**kw)
    except (SceneError, TypeError) as exc:
        raise SceneFileError(f"{path}: line contact: {exc}") from None


def _line_run(run, path):
    """Check the [run] table of a line-contact scene."""
    extra = set(run) - LINE_RUN_KEYS
    if extra:
        raise SceneFileError(
            f"{path}: [run] of a line contact ([indenter] kind = 'cylinder') "
            f"does not take {sorted(extra)}; it takes {sorted(LINE_RUN_KEYS)}."
        )
    method = run.pop("method", "line")
    if method != "line":
        raise SceneFileError(
            f"{path}: [run] method = {method!r}: line contact is solved by "
            'method = "line" (or leave method out).'
        )
    return run


def run_options(run: dict) -> dict:
    """Turn a [run] table into keyword arguments of :func:`femehl.solve`."""
    out = dict(run)
    if "dtheta_divisions" in out:
        n = out.pop("dtheta_divisions")
        if not isinstance(n, int) or n < 2:
            raise SceneFileError(
                f"[run] dtheta_divisions must be an integer >= 2 (dtheta = pi/n), got {n!r}."
            )
        out["dtheta"] = math.pi / n
    return out
