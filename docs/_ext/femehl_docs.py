"""Sphinx helpers of the femehl documentation (loaded by ``docs/conf.py``).

* ``.. femehl-solve-options::`` -- a table of every keyword ``femehl.solve`` takes, read
  from the signatures of ``solve``, the registered methods, the stepper, the linear
  solvers, the adaptive step controls and the automatic driver, with the descriptions
  of their numpydoc ``Parameters`` sections;
* ``.. femehl-toml-keys::`` -- the tables and keys of a TOML scene file, read from the
  registries of :mod:`femehl.problem.scenefile`;
* the example gallery: a copy of ``examples/`` under ``docs/_build`` (examples write
  their output into the folder they run in), and an image scraper that shows the PNGs an
  example writes (femehl's run folders close their figures).

A keyword or key that has no description makes the build warn, so fails it under ``-W``.
"""

from __future__ import annotations

import ast
import inspect
import shutil
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import Directive
from docutils.statemachine import StringList
from sphinx.util import logging

logger = logging.getLogger(__name__)

#: examples the gallery executes (each runs in seconds); the others are shown, not run
GALLERY_EXECUTED = (
    "custom_shape",
    "cylinder_winkler",
    "ellipsoid_sliding",
    "load_controlled",
    "rolling_traction",
)

GALLERY_HEADER = """\
Example gallery
===============

The scripts of ``examples/``, each a complete run you can copy.  The pages of the
examples that take seconds show the output and the pictures of a run made when these
pages were built (written to a temporary folder); ``paper_figures.py`` (about 15
minutes: the paper's finite-difference grid dominates) and ``textured_sphere.py``
(200,000 elements, about 40 minutes) are shown without being run.  The ``.toml`` twins of
the examples run the same scenes from the command line (``femehl run
examples/ellipsoid_sliding.toml``, see :doc:`/scene`).
"""


# -- example gallery -------------------------------------------------------------------


def prepare_gallery_sources(examples: Path, target: Path) -> Path:
    """Copy ``examples/*.py`` to ``target`` (only files whose text changed) with a header."""
    target.mkdir(parents=True, exist_ok=True)
    wanted = {"GALLERY_HEADER.rst": GALLERY_HEADER}
    for src in sorted(examples.glob("*.py")):
        wanted[src.name] = src.read_text()
    for old in target.glob("*"):
        if old.is_file() and old.name not in wanted:
            old.unlink()
    for name, text in wanted.items():
        dst = target / name
        if not dst.exists() or dst.read_text() != text:
            dst.write_text(text)
    return target


def example_argv(gallery_conf, script_vars):
    """``reset_argv`` hook: no command-line arguments, and the example's own ``__doc__``.

    sphinx-gallery runs an example with ``__doc__ = ""``; the examples that build an
    argparse parser take its description from their docstring's first line, so the real
    docstring is put back (this hook runs once the example's globals exist).
    """
    src = Path(script_vars["src_file"])
    script_vars["example_globals"]["__doc__"] = ast.get_docstring(ast.parse(src.read_text()))
    return []


_BEFORE: dict[Path, int] = {}


def _pngs(folder: Path) -> dict[Path, int]:
    return {p: p.stat().st_mtime_ns for p in sorted(folder.rglob("*.png"))}


def snapshot_pngs(gallery_conf, fname, when=None):
    """``reset_modules`` hook: remember the PNGs (and their times) before an example runs."""
    _BEFORE.clear()
    _BEFORE.update(_pngs(Path(gallery_conf["examples_dirs"][0])))


def written_png_scraper(block, block_vars, gallery_conf, **kwargs):
    """Image scraper: the PNGs the example wrote (new or rewritten) since it started."""
    from sphinx_gallery.scrapers import figure_rst

    folder = Path(block_vars["src_file"]).parent
    new = [p for p, t in _pngs(folder).items() if _BEFORE.get(p) != t]
    image_paths = []
    for png, image_path in zip(new, block_vars["image_path_iterator"], strict=False):
        shutil.copyfile(png, image_path)
        image_paths.append(image_path)
        _BEFORE[png] = png.stat().st_mtime_ns
    return figure_rst(image_paths, gallery_conf["src_dir"])


# -- tables from the code ----------------------------------------------------------------


def _param_docs(obj) -> dict[str, tuple[str, str]]:
    """name -> (type, description) from the numpydoc Parameters section of ``obj``."""
    from numpydoc.docscrape import NumpyDocString

    doc = inspect.getdoc(obj) or ""
    out = {}
    for p in NumpyDocString(doc)["Parameters"]:
        desc = " ".join(line.strip() for line in p.desc)
        for name in p.name.split(","):
            out[name.strip().lstrip("*")] = (p.type, desc)
    return out


def _split_default(typ: str, param: inspect.Parameter) -> tuple[str, str]:
    """(type, default): the docstring's ``default: X`` if it states one, else the signature's."""
    head, sep, stated = typ.partition("default:")
    if sep:
        return head.strip().rstrip(","), stated.strip()
    typ = typ.replace(", optional", "").strip()
    if param.default is inspect.Parameter.empty:
        return typ, ""
    return typ, f"``{param.default!r}``"


def _row(cells) -> list[str]:
    lines = []
    for i, cell in enumerate(cells):
        text = str(cell).strip() or " "
        lines.append(("   * - " if i == 0 else "     - ") + text)
    return lines


def _table(header, rows, widths) -> list[str]:
    lines = [
        ".. list-table::",
        "   :header-rows: 1",
        "   :widths: " + " ".join(str(w) for w in widths),
        "",
    ]
    lines += _row(header)
    for r in rows:
        lines += _row(r)
    return lines + [""]


#: options whose code has no numpydoc entry of its own
EXTRA_DOCS = {
    "max_elements": (
        "int",
        "Automatic mode: the largest mesh (cells) the refinement may reach; past it the run "
        'stops with ``result.info["auto"]["reached"]`` False (the estimate tells how far it got).',
    ),
    "max_wall": (
        "float",
        "Automatic mode: a time budget in seconds for the whole sequence; a finer run predicted "
        "to overrun it is not started (and a run in memory still going at the deadline is "
        'abandoned), the answer is the last finished run with ``result.info["auto"]["stopped"]`` '
        '"time budget" when it did not reach ``tol``.',
    ),
    "level": (
        "float",
        "Automatic mode: the first (coarsest) level of the scene-fitted mesh; each further "
        "run halves it (about twice the cells).",
    ),
}


class SolveOptions(Directive):
    """Every keyword of ``femehl.solve``, grouped by who consumes it."""

    has_content = False

    def run(self):
        from femehl import api, auto
        from femehl.discretize import METHODS, method_class
        from femehl.solver import adaptive, linsolve
        from femehl.solver.stepper import LaggedStepper

        method_class("fe")  # imports every registered discretization
        groups = []

        def group(title, owner, obj, skip=(), names=None):
            docs = _param_docs(obj)
            sig = inspect.signature(obj)
            rows = []
            for name, param in sig.parameters.items():
                if name in skip or param.kind in (param.VAR_KEYWORD, param.VAR_POSITIONAL):
                    continue
                if names is not None and name not in names:
                    continue
                typ, desc = docs.get(name) or EXTRA_DOCS.get(name) or ("", "")
                if not desc:
                    logger.warning(
                        f"femehl-solve-options: {owner}: keyword {name!r} has no description",
                        location=self.state_machine.get_source_and_line(self.lineno),
                    )
                typ, default = _split_default(typ, param)
                rows.append((f"``{name}``", typ, default, desc))
            groups.append((title, owner, rows))

        group("The run", "femehl.solve", api.solve, skip={"scene"})
        for key in sorted(METHODS):
            cls = METHODS[key]
            group(
                f'Discretization: ``method="{key}"``',
                f"{cls.__module__}.{cls.__qualname__}",
                cls,
                skip={"scene"},
            )
        group(
            "The stepper (every method)", "femehl.solver.stepper.LaggedStepper", LaggedStepper, skip={"disc"}
        )
        for key in sorted(linsolve.LINEAR_SOLVERS):
            sol = linsolve.LINEAR_SOLVERS[key]
            if inspect.signature(sol).parameters:
                group(
                    f'Linear solver ``linear_solver="{key}"``',
                    f"{sol.__module__}.{sol.__qualname__}",
                    sol,
                )
        group(
            "Adaptive time steps (expert mode with ``step_tol``)",
            "femehl.solver.adaptive.AdaptiveSteps",
            adaptive.AdaptiveSteps,
            names=set(adaptive.CONTROLS),
        )
        group(
            "Automatic mode (no ``dt``, no discretization option)",
            "femehl.accuracy.auto.solve_to_tolerance",
            auto.solve_to_tolerance,
            names={"max_elements", "max_wall", "level"},
        )

        lines = []
        for title, owner, rows in groups:
            lines += [f".. rubric:: {title}", "", f"Read by :obj:`{owner}`.", ""]
            lines += _table(("keyword", "type", "default", "meaning"), rows, (14, 16, 12, 58))
        return _parse(self, lines)


RUN_KEY_DOCS = {
    "method": ("solve ``method``", '"fe" (default), "fd"; "line" for a cylinder scene'),
    "scheme": ("solve ``scheme``", '"euler" (the paper\'s) or "bdf2"'),
    "t_end": ("solve ``t_end``", "end time, default 5"),
    "dt": ("solve ``dt``", "fixed time step (expert mode)"),
    "store_every": ("solve ``store_every``", "write fields every N steps (default 10 in a run folder)"),
    "mesh": ("FE ``mesh``", "a ladder name, ``fitted`` or a mesh file (relative to the scene file)"),
    "dr": ("FD ``dr``", "radial step"),
    "dtheta_divisions": ("FD ``dtheta = pi/N``", "N, an integer"),
    "linear_solver": ("stepper ``linear_solver``", '"gmres" or "lu"'),
    "tol": ("solve ``tol``", "the automatic mode's accuracy target"),
    "step_tol": ("solve ``step_tol``", "adaptive time steps with a mesh (expert mode)"),
    "operator": ("FE ``operator``", '"auto", "dense" or "fast"'),
    "operator_tol": ("FE ``operator_tol``", "the fast operator's relative error"),
    "max_wall": ("automatic ``max_wall``", "a time budget in seconds (automatic mode)"),
    "n_elements": ("line ``n_elements``", "number of P1 elements"),
    "grading": ("line ``grading``", '"uniform" or a size ratio >= 1'),
}

#: the [si] key the Python API has no parameter for
SI_LOAD = ("load", "float", "Imposed constant load [N] instead of the gap ramp (optional).")


def _kinds(registry) -> list[tuple[str, str, str]]:
    rows = []
    for kind in sorted(registry):
        cls = registry[kind]
        params = ", ".join(
            f"``{n}`` = {p.default!r}" if p.default is not inspect.Parameter.empty else f"``{n}``"
            for n, p in inspect.signature(cls).parameters.items()
        )
        summary = (inspect.getdoc(cls) or "").split("\n\n")[0].replace("\n", " ")
        rows.append(
            (f'``"{kind}"``', params or "(none)", f":class:`{cls.__module__}.{cls.__qualname__}`: {summary}")
        )
    return rows


class TomlKeys(Directive):
    """The tables and keys of a scene file."""

    has_content = False

    def run(self):
        from femehl.problem import scenefile

        lines = [".. rubric:: ``[indenter]`` kinds", ""]
        indenters = {k: v for k, v in scenefile.INDENTERS.items() if k != "shape"}
        lines += _table(("kind", "keys (default)", "shape"), _kinds(indenters), (14, 30, 56))
        lines += [
            '``kind = "heightmap"`` may read ``file = "map.npz"`` (arrays x, y, z, a path relative '
            'to the scene file) instead of x, y, z; ``kind = "cylinder"`` (R = 1) is line contact. '
            '``kind = "shape"`` (a Python function) exists only in Python.',
            "",
            ".. rubric:: ``[substrate]`` kinds",
            "",
        ]
        lines += _table(("kind", "keys (default)", "substrate"), _kinds(scenefile.SUBSTRATES), (14, 30, 56))
        lines += [
            ".. rubric:: Time functions: ``[motion.gap]``, ``[motion.velocity]``, ``[motion.load]``",
            "",
        ]
        lines += _table(
            ("kind", "keys (default)", "function"), _kinds(scenefile.TIME_FUNCTIONS), (14, 30, 56)
        )
        lines += [
            "``[fluid]`` takes only ``beta``; ``[domain]`` only ``L``.  ``[motion.load]`` may also "
            "be a plain number (a constant load).",
            "",
            ".. rubric:: ``[run]`` keys",
            "",
        ]
        rows = []
        for key in sorted(scenefile.RUN_KEYS | scenefile.LINE_RUN_KEYS):
            if key not in RUN_KEY_DOCS:
                logger.warning(
                    f"femehl-toml-keys: [run] key {key!r} has no description",
                    location=self.state_machine.get_source_and_line(self.lineno),
                )
            same, desc = RUN_KEY_DOCS.get(key, ("", ""))
            where = []
            if key in scenefile.RUN_KEYS:
                where.append("disk")
            if key in scenefile.LINE_RUN_KEYS:
                where.append("line")
            rows.append((f"``{key}``", " and ".join(where), same, desc))
        lines += _table(("key", "scenes", "same as", "meaning"), rows, (18, 14, 28, 40))
        lines += [
            ".. rubric:: ``[si]`` keys (the paper's experiment in SI units)",
            "",
            "The parameters of :class:`femehl.problem.scene.Dimensional` and of its "
            ":meth:`~femehl.problem.scene.Dimensional.scene`, and ``load``:",
            "",
        ]
        from femehl.problem.scene import Dimensional

        si = {**_param_docs(Dimensional), **_param_docs(Dimensional.scene)}
        rows = [(f"``{k}``", typ, desc) for k, (typ, desc) in si.items()]
        rows.append((f"``{SI_LOAD[0]}``", SI_LOAD[1], SI_LOAD[2]))
        lines += _table(("key", "type", "meaning"), rows, (15, 25, 60))
        return _parse(self, lines)


def _parse(directive, lines):
    directive.state.document.settings.env.note_reread()  # the tables follow the code, not the page
    node = nodes.container()
    source, _ = directive.state_machine.get_source_and_line(directive.lineno)
    directive.state.nested_parse(StringList(lines, source=source), directive.content_offset, node)
    return node.children


def setup(app):
    app.add_directive("femehl-solve-options", SolveOptions)
    app.add_directive("femehl-toml-keys", TomlKeys)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}


__all__ = [
    "GALLERY_EXECUTED",
    "example_argv",
    "prepare_gallery_sources",
    "snapshot_pngs",
    "written_png_scraper",
    "setup",
]
