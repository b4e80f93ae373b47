"""Triangulated disks for the P1 finite-element Reynolds solver.

A mesh is a :class:`DiskMesh` (a :class:`skfem.MeshTri` of the disk ``r <= L`` or of the
half disk ``y >= 0``, with its radius and origin).  :func:`graded_disk` meshes it with gmsh
under a radial size function, the :data:`LADDER` rungs (``coarse`` to ``xfine``) each
doubling the elements; :func:`sized_disk` under any size field; :func:`load_mesh` reads
and checks any triangulation.  The grading, the ladder files and every check:
docs/design.md section 4 ("The meshes") and ``meshes/README.md``.
"""

from __future__ import annotations

import contextlib
import difflib
import hashlib
import json
import math
import os
import pathlib
import tempfile
from dataclasses import dataclass, field

import numpy as np
import skfem

from femehl.errors import MeshError

__all__ = [
    "LADDER",
    "LADDER_RATIO",
    "MAX_GMSH_ELEMENTS",
    "FAST_BYTES_PER_ELEMENT",
    "MEMORY_FRACTION",
    "DiskMesh",
    "areas",
    "centroids",
    "check_mesh_memory",
    "estimate_elements",
    "graded_disk",
    "sized_disk",
    "LinearSizes",
    "ladder_path",
    "load_mesh",
    "machine_memory",
    "dense_bytes",
    "operator_bytes",
]

#: Relative tolerance of "on the circle r = L" / "on the line y = 0" / "radius == L".
_RTOL_BOUNDARY = 1e-9
#: A half disk may have nodes down to y = -_YTOL_HALF * L (round-off).
_YTOL_HALF = 1e-12
#: A triangle with area <= _AREA_DEGENERATE * L**2 is degenerate.
_AREA_DEGENERATE = 1e-12
#: Floor of the relative area tolerance of the coverage check.
_AREA_RTOL_MIN = 1e-3
#: Width (normalized units) over which h goes from h_edge to h_contact.
_EDGE_TRANSITION = 0.15

_READABLE = "e.g. gmsh .msh, VTK .vtu or XDMF .xdmf"

#: Refuse a mesh whose run would need more than this fraction of the machine's physical
#: memory (dense: :func:`dense_bytes`; fast: :data:`FAST_BYTES_PER_ELEMENT`).  Both are
#: counts of what the run holds at its peak, checked against measured peaks, so the rest
#: is the interpreter, the mesh and the sparse operators (about 0.8 GB at 44,792 elements).
MEMORY_FRACTION = 0.8
#: Besides the dense operator ``C`` (elements x free nodes), the dense path holds square
#: ``free nodes x free nodes`` arrays: one film product ``F C`` per term that has one (the
#: squeeze term always, the Couette term once the surface slides: 8 bytes an entry each),
#: and the system's LU, 4 bytes an entry in the default solver (a single-precision
#: preconditioner), 8 with ``linear_solver="lu"``; one LU at a time (a refresh frees the
#: old one before it forms the new matrix, which LAPACK factors in place).  Measured
#: (benchmarks/fast_operator.md, peak RSS of the whole process) on the paper case at
#: 44,792 elements and 22,454 free nodes over the whole run (both film products): 18.9 GB,
#: counted 18.1 GB; before the solver stopped holding the old LU during a refresh,
#: 20.9 GB (and 21.3 GB at 45,156 elements).
_FILM_PRODUCTS = 2
#: graded_disk refuses sizes that would make more elements than this (gmsh would run
#: for hours and the solver could not hold the operator anyway).
MAX_GMSH_ELEMENTS = 2_000_000


@dataclass(frozen=True)
class DiskMesh:
    """A checked triangulation of the disk ``r <= L`` or the half disk ``y >= 0``.

    Build one with :func:`load_mesh` or :func:`graded_disk`: they check the mesh
    and orient every triangle counterclockwise.

    Attributes
    ----------
    mesh : skfem.MeshTri
        Linear triangles; nodes ``mesh.p`` of shape ``(2, n)``, elements
        ``mesh.t`` of shape ``(3, ne)``, every triangle counterclockwise.
    L : float
        Disk radius.
    half : bool
        True: half disk ``y >= 0`` with mirror line ``y = 0``; False: full disk.
    name : str
        Ladder name or file path the mesh came from (``"generated"``,
        ``"<MeshTri>"`` ... otherwise).
    """

    mesh: skfem.MeshTri
    L: float
    half: bool
    name: str


# ---------------------------------------------------------------------------
# ladder


#: Ratio of the mesh sizes of consecutive ladder rungs (~ sqrt(2); 1.45 puts the
#: element counts of all four rungs in their target ranges).
LADDER_RATIO = 1.45


def _rung(k: int) -> dict:
    """Sizes of rung ``k``: the coarse sizes divided by ``LADDER_RATIO**k``."""
    s = LADDER_RATIO ** (-k)
    return {
        "h_far": round(0.44 * s, 6),
        "h_contact": round(0.138 * s, 6),
        "h_edge": round(0.059 * s, 6),
        "r_contact": 1.3,
        "r_edge": (0.8, 1.2),
    }


#: The mesh ladder: name -> keyword arguments of :func:`graded_disk` (sizes in
#: normalized units).  Consecutive rungs differ by the factor ``LADDER_RATIO =
#: 1.45`` (about ``sqrt(2)``) in every mesh size, hence about 2.05 in element
#: count.  Element counts of the half disk, ``L = 2``: coarse 1468, medium 2982,
#: fine 6092, xfine 12660 (full disk: about twice); see ``meshes/README.md``.
LADDER: dict[str, dict] = {name: _rung(k) for k, name in enumerate(("coarse", "medium", "fine", "xfine"))}

_MESHES_DIR = pathlib.Path(__file__).resolve().parents[2] / "meshes"
_USER_CACHE = pathlib.Path("~/.cache/femehl")


def _ladder_filename(name: str, half: bool) -> str:
    return f"{'half' if half else 'full'}_{name}.msh"


def _check_ladder_name(name) -> None:
    if not isinstance(name, str) or name not in LADDER:
        raise MeshError(f"unknown mesh ladder name {name!r}; use one of {', '.join(LADDER)}")


def ladder_path(name: str, half: bool = True) -> pathlib.Path:
    """Path of the gmsh file of a ladder mesh, generating it if missing.

    Parameters
    ----------
    name : str
        A :data:`LADDER` name: ``"coarse"``, ``"medium"``, ``"fine"`` or
        ``"xfine"``.
    half : bool, default True
        Half disk (``meshes/half_<name>.msh``) or full disk
        (``meshes/full_<name>.msh``).

    Returns
    -------
    pathlib.Path
        ``<repo>/meshes/<half|full>_<name>.msh`` if it exists.  Otherwise the
        mesh is generated with ``graded_disk(L=2.0, half=half, **LADDER[name])``
        and written there if the ``meshes`` folder exists and is writable, else
        to ``~/.cache/femehl/<half|full>_<name>-<hash>.msh`` (the hash of the
        ladder sizes keeps a stale cache from being used); that path is
        returned.

    Raises
    ------
    MeshError
        If ``name`` is not a ladder name.
    """
    _check_ladder_name(name)
    half = bool(half)
    fname = _ladder_filename(name, half)
    shipped = _MESHES_DIR / fname
    if shipped.is_file():
        return shipped
    key = json.dumps(LADDER[name], sort_keys=True).encode()
    tag = hashlib.sha256(key).hexdigest()[:8]
    cached = _USER_CACHE.expanduser() / f"{fname[:-4]}-{tag}.msh"
    if cached.is_file():
        return cached
    dm = graded_disk(L=2.0, half=half, name=name, **LADDER[name])
    if _MESHES_DIR.is_dir() and os.access(_MESHES_DIR, os.W_OK):
        try:
            _write_msh(dm, shipped)
            return shipped
        except OSError:
            pass
    try:
        cached.parent.mkdir(parents=True, exist_ok=True)
        _write_msh(dm, cached)
    except OSError as exc:
        raise MeshError(
            f"cannot cache ladder mesh {name!r} in {_MESHES_DIR} or {cached.parent} "
            f"({exc}); make one of them writable, or pass "
            f"graded_disk(**LADDER[{name!r}]) to the solver"
        ) from exc
    return cached


def _write_msh(dm: DiskMesh, path: pathlib.Path) -> None:
    """Write ``dm`` as a gmsh 4.1 (binary) file, atomically (tmp file + rename)."""
    import meshio

    path = pathlib.Path(path)
    m = meshio.Mesh(dm.mesh.p.T.copy(), [("triangle", dm.mesh.t.T.astype(np.int64))])
    fd, tmp = tempfile.mkstemp(suffix=".msh", dir=path.parent)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes it private
    try:
        meshio.write(tmp, m, file_format="gmsh")
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


# ---------------------------------------------------------------------------
# size and memory guards


def machine_memory() -> int | None:
    """Physical memory of this machine in bytes, or None if the OS does not say."""
    try:
        n = int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError, TypeError):
        return None
    return n if n > 0 else None


def operator_bytes(n_elements: int, n_free: int) -> int:
    """Bytes of the dense elastic operator as it is built (elements x free nodes x 8; a large
    one is then kept in single precision, :mod:`femehl.elastic.dense`), before the LU copies."""
    return int(n_elements) * int(n_free) * 8


def dense_bytes(n_elements: int, n_free: int, lu_itemsize: int = 4) -> int:
    """Bytes a dense-path run holds at its peak: ``C``, the film products, the LU.

    ``lu_itemsize``: 4 for the default solver (its LU is a single-precision
    preconditioner), 8 for ``linear_solver="lu"``.  See :data:`_FILM_PRODUCTS`.
    """
    square = int(n_free) * int(n_free)
    return operator_bytes(n_elements, n_free) + (8 * _FILM_PRODUCTS + int(lu_itemsize)) * square


def _gb(n: float) -> str:
    return f"{n / 1e9:.3g} GB"


#: bytes per element of a run with the fast (hierarchical) elastic operator: operator,
#: preconditioner (with its coarse space) and solver, an upper bound of the measured peak
#: memory per element from 89,000 elements on (benchmarks/fast_operator.md, single-precision
#: far factors, 3e0e5c7: 26.3-29.4 kB at 89,206, 27.4-27.5 kB at 178,416 and 26.0 kB at
#: 514,644 half-disk elements, 26.9 kB at 203,152 full-disk textured ones; the order-11
#: operator, 42696ab: 30.2, 29.6 and 27.4 kB, textured 27.6 kB; smaller meshes, with the
#: interpreter's own ~0.1 GB, are far from any limit)
FAST_BYTES_PER_ELEMENT = 32_000


def dense_fits(n_elements: int, n_free: int, memory: int | None = None, lu_itemsize: int = 4) -> bool:
    """True when a dense-path run fits in ``MEMORY_FRACTION`` of the memory (or it is unknown)."""
    memory = machine_memory() if memory is None else memory
    return memory is None or dense_bytes(n_elements, n_free, lu_itemsize) <= MEMORY_FRACTION * memory


def check_mesh_memory(
    n_elements: int,
    n_free: int,
    name: str,
    memory: int | None = None,
    operator: str = "dense",
    lu_itemsize: int = 4,
) -> None:
    """Raise MeshError if a run on this mesh would not fit in memory.

    ``operator="dense"``: :func:`dense_bytes` (the ``elements x free nodes`` float64
    operator, the film products and the LU, ``lu_itemsize`` bytes an entry);
    ``operator="fast"``: :data:`FAST_BYTES_PER_ELEMENT` per element (a run with the
    hierarchical operator of :mod:`femehl.elastic.hmatrix`).  Refused above
    :data:`MEMORY_FRACTION` of the physical memory.  ``memory``: default
    :func:`machine_memory`; no check if it is unknown.
    """
    memory = machine_memory() if memory is None else memory
    if memory is None:
        return
    if operator == "fast":
        need = FAST_BYTES_PER_ELEMENT * int(n_elements)
        if need > MEMORY_FRACTION * memory:
            raise MeshError(
                f"mesh {name}: {n_elements} elements need about {_gb(need)} even with the fast "
                f"elastic operator ({FAST_BYTES_PER_ELEMENT // 1000} kB per element), more than "
                f"{MEMORY_FRACTION:.0%} of this machine's {_gb(memory)} of memory; use larger mesh "
                "sizes (a larger level) or a machine with more memory"
            )
        return
    if not dense_fits(n_elements, n_free, memory, lu_itemsize):
        raise MeshError(
            f"mesh {name}: {n_elements} elements and about {n_free} free nodes need a dense elastic "
            f"operator of {_gb(operator_bytes(n_elements, n_free))} (elements x free nodes x 8 bytes), "
            f"about {_gb(dense_bytes(n_elements, n_free, lu_itemsize))} with the film products and "
            f"the LU, more than {MEMORY_FRACTION:.0%} of this machine's {_gb(memory)} of memory; use "
            f"operator='fast' (or 'auto', the default), a coarser mesh (a ladder name: "
            f"{', '.join(LADDER)}) or larger mesh sizes"
        )


def estimate_elements(L, half, h) -> float:
    """About how many triangles gmsh makes under the size function ``h(r)``.

    An equilateral triangle of side ``h`` has area ``sqrt(3) h^2 / 4``, so the count
    is ``int 4 / (sqrt(3) h(r)^2) dA`` over the (half) disk; the ladder meshes have
    about 12 % more (gmsh's triangles are not all equilateral).
    """
    r = np.linspace(0.0, L, 4001)
    return _element_integral(r, L, half, h)


def _element_integral(r, L, half, h) -> float:
    with np.errstate(over="ignore"):
        dens = np.array([1.0 / h(float(x)) ** 2 for x in r]) * r
    span = math.pi if half else 2.0 * math.pi
    return float(span * np.trapezoid(dens, r) * 4.0 / math.sqrt(3.0))


# ---------------------------------------------------------------------------
# generation


def _size_function(L, h_far, h_contact, h_edge, r_contact, r_edge):
    """The radial mesh size ``h(r)`` of :func:`graded_disk` (scalar ``r``)."""
    a, b = r_edge

    def h(r: float) -> float:
        if r <= r_contact or r_contact >= L:
            base = h_contact
        else:
            base = h_contact + (h_far - h_contact) * min((r - r_contact) / (L - r_contact), 1.0)
        d = max(a - r, 0.0, r - b)  # distance to the annulus
        edge = h_edge + (h_contact - h_edge) * d / _EDGE_TRANSITION
        return min(base, edge)

    return h


def graded_disk(
    L: float = 2.0,
    half: bool = True,
    h_far: float = 0.25,
    h_contact: float = 0.05,
    h_edge: float = 0.02,
    r_contact: float = 1.3,
    r_edge: tuple[float, float] = (0.8, 1.2),
    name: str = "generated",
) -> DiskMesh:
    """Mesh the disk (or half disk) of radius ``L`` with gmsh, graded radially.

    Parameters
    ----------
    L : float, default 2.0
        Disk radius.
    half : bool, default True
        True: half disk ``y >= 0`` (boundary: the arc ``r = L, y >= 0`` and the
        mirror line ``y = 0`` from ``-L`` to ``L``).  False: full disk.
    h_far : float, default 0.25
        Mesh size at ``r = L``.
    h_contact : float, default 0.05
        Mesh size for ``r < r_contact`` away from the edge annulus.
    h_edge : float, default 0.02
        Mesh size in the annulus ``r_edge[0] <= r <= r_edge[1]``.
    r_contact : float, default 1.3
        Radius beyond which the size grows linearly in ``r`` from ``h_contact``
        to ``h_far`` at ``r = L``.
    r_edge : tuple of float, default (0.8, 1.2)
        Inner and outer radius of the refined annulus (contact edge and exit
        constriction).  Sizes go linearly from ``h_edge`` to ``h_contact``
        over 0.15 on either side of it.
    name : str, default "generated"
        Stored as :attr:`DiskMesh.name`.

    Returns
    -------
    DiskMesh
        Checked as by :func:`load_mesh`, counterclockwise triangles, boundary
        nodes exactly on ``r = L`` and ``y = 0``, a node at the origin.  The
        same arguments give the same mesh (one thread, fixed seed, no gmsh
        configuration files read).

    Raises
    ------
    MeshError
        If a size or radius is not positive and finite, or ``r_edge`` is not
        an increasing pair.
    """
    vals = {"L": L, "h_far": h_far, "h_contact": h_contact, "h_edge": h_edge, "r_contact": r_contact}
    for k, v in vals.items():
        if not (isinstance(v, (int, float, np.number)) and math.isfinite(v) and v > 0):
            raise MeshError(f"graded_disk: {k} = {v!r} must be a positive finite number")
    try:
        a, b = (float(x) for x in r_edge)
    except (TypeError, ValueError) as exc:
        raise MeshError(f"graded_disk: r_edge = {r_edge!r} must be a pair (r_in, r_out)") from exc
    if not (math.isfinite(a) and math.isfinite(b) and 0 <= a < b):
        raise MeshError(f"graded_disk: r_edge = {r_edge!r} must satisfy 0 <= r_in < r_out")
    if max(h_far, h_contact, h_edge) > L:
        raise MeshError(
            f"graded_disk: mesh sizes ({h_far}, {h_contact}, {h_edge}) must not exceed L = {L}; "
            "pass smaller sizes"
        )
    L = float(L)
    h = _size_function(L, float(h_far), float(h_contact), float(h_edge), float(r_contact), (a, b))
    # sample finely where h dips (the edge annulus and its transitions), then refuse
    # sizes that would make gmsh run for hours or the operator overflow the memory
    w = _EDGE_TRANSITION
    r = np.union1d(
        np.linspace(0.0, L, 4001), np.linspace(max(a - w, 0.0), max(min(b + w, L), max(a - w, 0.0)), 2001)
    )
    ne = _element_integral(r[r <= L], L, bool(half), h)
    if not ne <= MAX_GMSH_ELEMENTS:
        raise MeshError(
            f"graded_disk: sizes h_far = {h_far}, h_contact = {h_contact}, h_edge = {h_edge} on L = "
            f"{L:g} would make about {ne:.3g} elements, more than {MAX_GMSH_ELEMENTS:.0e} (gmsh "
            "would run for hours); pass larger "
            "mesh sizes"
        )
    check_mesh_memory(int(ne), int(ne / 2), f"graded_disk(L={L:g}, ...) (estimated)", operator="fast")
    return sized_disk(L, bool(half), lambda x, y: h(math.hypot(x, y)), name)


@dataclass(frozen=True, eq=False)
class LinearSizes:
    """A size field linear on triangles: ``values`` at ``nodes`` (2, n) of ``triangles``
    (3, ne), ``far`` outside them.  Callable as ``h(x, y)``; :func:`sized_disk` hands it to
    gmsh as a background view, read in gmsh's own code (a Python callback per point cost
    0.9 s for a mesh of 6,000 cells; gmsh also reads the view just outside the triangles,
    on the sliver between a polygonal boundary and the arc)."""

    nodes: np.ndarray
    triangles: np.ndarray
    values: np.ndarray
    far: float
    _interpolator: object = field(default=None, init=False, repr=False)  # built on the first call

    def __call__(self, x: float, y: float) -> float:
        if self._interpolator is None:
            import matplotlib.tri as mtri

            tri = mtri.Triangulation(self.nodes[0], self.nodes[1], self.triangles.T)
            object.__setattr__(self, "_interpolator", mtri.LinearTriInterpolator(tri, self.values))
        v = self._interpolator(x, y)
        return float(self.far) if np.ma.is_masked(v) else float(v)

    def gmsh_list(self) -> np.ndarray:
        """gmsh's list data of scalar triangles ("ST"): per triangle x1..3, y1..3, z1..3, v1..3."""
        p, t = self.nodes, self.triangles
        return np.concatenate([p[0, t].T, p[1, t].T, np.zeros((t.shape[1], 3)), self.values[t].T], axis=1)


def sized_disk(L: float, half: bool, size, name: str = "generated") -> DiskMesh:
    """Mesh the (half) disk of radius ``L`` with gmsh under the size field ``size(x, y)``
    (a :class:`LinearSizes` is read by gmsh itself).

    The machinery of :func:`graded_disk` (same gmsh options: Frontal-Delaunay, one
    thread, fixed seed) for any scalar size function of the position, e.g. the
    scene-fitted fields of :mod:`femehl.discretize.fitted`.  The caller guards the element
    count (:data:`MAX_GMSH_ELEMENTS`, :func:`check_mesh_memory`) before calling.

    Returns
    -------
    DiskMesh
        Checked as by :func:`load_mesh`; boundary nodes exactly on ``r = L`` / ``y = 0``.
    """
    L = float(L)
    p, t, on_arc, on_line = _gmsh_disk(L, bool(half), size)
    # Exact boundary: arc nodes onto r = L, mirror-line nodes onto y = 0.
    r = np.hypot(p[0, on_arc], p[1, on_arc])
    p[:, on_arc] *= L / r
    p[1, on_line] = 0.0
    p, t, half = _normalize(p, t, L, bool(half), name)
    return DiskMesh(_make_meshtri(p, t), L, half, name)


_GMSH_OPTIONS = {
    "General.Terminal": 0,
    "General.Verbosity": 0,
    "General.NumThreads": 1,
    "Mesh.MaxNumThreads2D": 1,
    "Mesh.RandomSeed": 1,
    "Mesh.Algorithm": 6,  # Frontal-Delaunay
    "Mesh.MeshSizeFromPoints": 0,
    "Mesh.MeshSizeFromCurvature": 0,
    "Mesh.MeshSizeExtendFromBoundary": 0,
    "Mesh.Smoothing": 3,
}


def _gmsh_disk(L, half, h):
    """Run gmsh under the size field ``h(x, y)``; return nodes (2, n), triangles (3, ne),
    masks of arc / line nodes."""
    import gmsh

    owner = not gmsh.isInitialized()
    saved = {}
    model = None
    views = []
    try:
        if owner:
            gmsh.initialize(readConfigFiles=False, interruptible=False)
        for k, v in {**_GMSH_OPTIONS, "Mesh.MeshSizeMax": 1e22}.items():
            if not owner:
                saved[k] = gmsh.option.getNumber(k)
            gmsh.option.setNumber(k, v)
        if not owner:
            previous_model = gmsh.model.getCurrent()
        model = f"femehl_disk_{os.getpid()}_{id(h)}"
        gmsh.model.add(model)
        geo = gmsh.model.geo
        c = geo.addPoint(0, 0, 0)
        pe = geo.addPoint(L, 0, 0)
        pn = geo.addPoint(0, L, 0)
        pw = geo.addPoint(-L, 0, 0)
        arcs = [geo.addCircleArc(pe, c, pn), geo.addCircleArc(pn, c, pw)]
        if half:
            lines = [geo.addLine(pw, c), geo.addLine(c, pe)]
            loop = geo.addCurveLoop(arcs + lines)
        else:
            ps = geo.addPoint(0, -L, 0)
            arcs += [geo.addCircleArc(pw, c, ps), geo.addCircleArc(ps, c, pe)]
            lines = []
            loop = geo.addCurveLoop(arcs)
        surf = geo.addPlaneSurface([loop])
        geo.synchronize()
        if not half:
            gmsh.model.mesh.embed(0, [c], 2, surf)  # a node at the origin
        if isinstance(h, LinearSizes):  # gmsh interpolates the view; outside it: far
            view = gmsh.view.add(f"{model}_sizes")
            views.append(view)
            data = h.gmsh_list()
            gmsh.view.addListData(view, "ST", data.shape[0], data.ravel().tolist())
            background = gmsh.model.mesh.field.add("PostView")
            gmsh.model.mesh.field.setNumber(background, "ViewTag", view)
            gmsh.model.mesh.field.setAsBackgroundMesh(background)
            gmsh.option.setNumber("Mesh.MeshSizeMax", float(h.far))
        else:
            gmsh.model.mesh.setSizeCallback(lambda dim, tag, x, y, z, lc: h(x, y))
        gmsh.model.mesh.generate(2)

        tags, coords, _ = gmsh.model.mesh.getNodes()
        p = coords.reshape(-1, 3)[:, :2].T.copy()
        index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
        index[tags.astype(np.int64)] = np.arange(tags.size)
        _, node_tags = gmsh.model.mesh.getElementsByType(2)
        t = index[node_tags.astype(np.int64)].reshape(-1, 3).T.copy()

        def nodes_of(curves):
            m = np.zeros(p.shape[1], dtype=bool)
            for cu in curves:
                nt, _, _ = gmsh.model.mesh.getNodes(1, cu, includeBoundary=True)
                m[index[nt.astype(np.int64)]] = True
            return m

        return p, t, nodes_of(arcs), nodes_of(lines)
    finally:
        if owner:
            gmsh.finalize()
        else:
            for view in views:
                with contextlib.suppress(Exception):
                    gmsh.view.remove(view)
            if model is not None:
                try:
                    gmsh.model.setCurrent(model)
                    gmsh.model.remove()
                    gmsh.model.setCurrent(previous_model)
                except Exception:  # noqa: BLE001, S110  # pragma: no cover - best effort
                    pass
            for k, v in saved.items():
                gmsh.option.setNumber(k, v)


# ---------------------------------------------------------------------------
# loading and checks


def load_mesh(spec, L: float = 2.0, half: bool | None = None) -> DiskMesh:
    """Load and check a triangulation of the disk ``r <= L`` (or half disk).

    Parameters
    ----------
    spec : str, pathlib.Path, skfem.MeshTri or DiskMesh
        A :data:`LADDER` name (``"coarse"``, ``"medium"``, ``"fine"``,
        ``"xfine"``); a path to any file meshio reads (only its ``triangle``
        cells are used, ``z`` is dropped); a :class:`skfem.MeshTri`; or a
        :class:`DiskMesh` (checked against ``L`` and ``half`` like any other
        input, and returned as is if it passes the checks unchanged).
    L : float, default 2.0
        Disk radius the mesh must have.  For a ladder name with ``L != 2`` the
        mesh is generated with ``graded_disk(L=L, half=half, **LADDER[name])``
        (same sizes in normalized units, not a scaled copy).
    half : bool or None, default None
        Half disk (``y >= 0``) or full disk.  None: True for a ladder name,
        the stored flag for a :class:`DiskMesh`, otherwise detected from the
        nodes (half if every ``y >= -1e-12 L``).

    Returns
    -------
    DiskMesh
        Counterclockwise triangles, no unused nodes, boundary nodes snapped
        exactly onto ``r = L`` / ``y = 0``.

    Raises
    ------
    MeshError
        If the file is missing or unreadable, has no triangles, or the mesh
        fails a check (docs/design.md section 4); the message says how to fix
        it.

    Notes
    -----
    Area tolerance.  A triangulation whose boundary nodes lie on the circle
    is the inscribed polygon: each boundary chord of length ``c`` cuts off a
    circular segment of area ``L^2 (theta - sin theta) / 2 ~ c^3 / (12 L)``
    (``theta = c / L``), so chords of length ``h`` lose
    ``(2 pi L / h) * h^3 / (12 L) = pi h^2 / 6`` in all, a relative deficit
    ``delta = h^2 / (6 L^2)`` (half disk: the same).  With ``h = h_far = 0.25``,
    ``L = 2`` that is ``2.6e-3``.  The check accepts a relative area error up
    to ``max(1e-3, 2 delta)``, with ``delta = sum(c^3) / (12 L A0)`` summed
    over the mesh's own boundary chords on the circle (``A0`` the exact area).
    """
    if isinstance(spec, DiskMesh):
        _check_memory_of(spec.mesh.t, spec.name)
        p0 = np.asarray(spec.mesh.p)
        t0 = np.asarray(spec.mesh.t)
        want_half = spec.half if half is None else bool(half)
        p, t, h = _normalize(p0.copy(), t0.copy(), L, want_half, spec.name)
        if (
            h == spec.half
            and float(L) == spec.L
            and p.shape == p0.shape
            and t.shape == t0.shape
            and np.array_equal(p, p0)
            and np.array_equal(t, t0)
        ):
            return spec
        return DiskMesh(_make_meshtri(p, t), float(L), h, spec.name)

    if isinstance(spec, skfem.MeshTri):
        _check_memory_of(spec.t, "<MeshTri>")
        p = np.array(spec.p[:2], dtype=np.float64)  # copies
        t = np.array(spec.t[:3], dtype=np.int64)
        p, t, h = _normalize(p, t, L, half, "<MeshTri>")
        return DiskMesh(_make_meshtri(p, t), float(L), h, "<MeshTri>")

    if isinstance(spec, str) and spec == "fitted" and not pathlib.Path(spec).exists():
        raise MeshError(
            "mesh 'fitted' depends on the scene: pass mesh=femehl.discretize.fitted.fitted_disk(scene, "
            "t_end) (a DiskMesh refined at that scene's contact) instead of the name"
        )
    if isinstance(spec, str) and spec in LADDER:
        half = True if half is None else bool(half)
        _check_l(L)
        if float(L) != 2.0:
            return graded_disk(L=float(L), half=half, name=spec, **LADDER[spec])
        path = ladder_path(spec, half)
        p, t = _read_file(path, 2.0, "gmsh")
        _check_memory_of(t, spec)
        p, t, h = _normalize(p, t, 2.0, half, spec)
        return DiskMesh(_make_meshtri(p, t), 2.0, h, spec)

    if isinstance(spec, (str, os.PathLike)):
        path = pathlib.Path(spec)
        _check_l(L)
        p, t = _read_file(path, L)
        _check_memory_of(t, str(path))
        p, t, h = _normalize(p, t, L, half, str(path))
        return DiskMesh(_make_meshtri(p, t), float(L), h, str(path))

    raise MeshError(
        f"cannot load a mesh from a {type(spec).__name__}; pass a ladder name "
        f"({', '.join(LADDER)}), a mesh file path, an skfem.MeshTri or a DiskMesh"
    )


def centroids(dm: DiskMesh) -> np.ndarray:
    """Element centroids.

    Parameters
    ----------
    dm : DiskMesh
        The mesh.

    Returns
    -------
    numpy.ndarray
        Shape ``(ne, 2)``: ``x, y`` of each triangle's centroid.
    """
    p, t = dm.mesh.p, dm.mesh.t
    return p[:, t].mean(axis=1).T.copy()


def areas(dm: DiskMesh) -> np.ndarray:
    """Element areas.

    Parameters
    ----------
    dm : DiskMesh
        The mesh.

    Returns
    -------
    numpy.ndarray
        Shape ``(ne,)``, positive (the triangles are counterclockwise).
    """
    return np.abs(_signed_areas(dm.mesh.p, dm.mesh.t))


def _signed_areas(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    x0, y0 = p[0, t[0]], p[1, t[0]]
    x1, y1 = p[0, t[1]], p[1, t[1]]
    x2, y2 = p[0, t[2]], p[1, t[2]]
    return 0.5 * ((x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0))


def _make_meshtri(p: np.ndarray, t: np.ndarray) -> skfem.MeshTri:
    # sort_t=False: keep the counterclockwise node order (skfem 12 sorts by default).
    return skfem.MeshTri(
        np.ascontiguousarray(p, dtype=np.float64),
        np.ascontiguousarray(t, dtype=np.int32),
        sort_t=False,
    )


def _check_memory_of(t, name) -> None:
    """check_mesh_memory for triangles ``t`` (3, ne): free nodes estimated by the used nodes."""
    t = np.asarray(t)
    if t.ndim == 2 and t.shape[0] >= 3 and t.size:
        check_mesh_memory(t.shape[1], np.unique(t[:3]).size, name, operator="fast")


def _check_l(L) -> None:
    if not (isinstance(L, (int, float, np.number)) and math.isfinite(L) and L > 0):
        raise MeshError(f"L = {L!r} must be a positive finite number (the disk radius)")


def _meshio_read(path: pathlib.Path, file_format: str | None):
    """``meshio.read`` without its side effects: it prints the error of each format it tries
    and calls ``sys.exit`` when none works. Redirecting sys.stdout/stderr around it would
    swap them for the whole process (a sweep's other threads print meanwhile), so the
    candidate formats are tried here, as meshio does, and their errors collected."""
    import meshio
    from meshio import _helpers

    formats, ext = ([file_format] if file_format else []), ""
    for suffix in reversed(path.suffixes if not file_format else []):
        ext = (suffix + ext).lower()
        formats += meshio.extension_to_filetypes.get(ext, [])
    if not formats:
        raise meshio.ReadError(f"no format meshio knows ends in {path.suffix or 'no suffix'!r}")
    said = []
    for fmt in formats:
        if fmt not in _helpers.reader_map:
            raise meshio.ReadError(f"unknown file format {fmt!r}")
        try:
            return _helpers.reader_map[fmt](str(path))
        except meshio.ReadError as exc:
            said.append(f"as {fmt}: {exc}")
    raise meshio.ReadError("; ".join(said))


def _read_file(path: pathlib.Path, L: float = 2.0, file_format: str | None = None):
    """Read the triangles of a mesh file: nodes (2, n), triangles (3, ne)."""

    if path.is_dir():
        raise MeshError(
            f"mesh path '{path}' is a directory, not a mesh file; pass a mesh file in it "
            f"({_READABLE}) or a ladder name ({', '.join(LADDER)})"
        )
    if not path.exists():
        close = difflib.get_close_matches(str(path), list(LADDER), n=1)
        hint = f" (did you mean the ladder mesh {close[0]!r}?)" if close else ""
        raise MeshError(
            f"mesh file '{path}' does not exist{hint}; pass an existing mesh file ({_READABLE}) "
            f"or a ladder name ({', '.join(LADDER)})"
        )
    if not path.is_file():
        raise MeshError(f"mesh path '{path}' is not a regular file; pass a mesh file ({_READABLE})")
    if not os.access(path, os.R_OK):
        raise MeshError(
            f"mesh file '{path}' is not readable (permission denied); fix its "
            "permissions or pass a copy you can read"
        )
    try:
        m = _meshio_read(path, file_format)
    except Exception as exc:  # noqa: BLE001 - meshio raises many kinds: wrap them all
        raise MeshError(
            f"'{path}' is not a mesh meshio can read ({type(exc).__name__}: {exc}); "
            f"pass a file in a format meshio reads, {_READABLE}"
        ) from None
    blocks = [np.asarray(c.data) for c in m.cells if c.type == "triangle"]
    if not blocks:
        found = sorted({c.type for c in m.cells}) or ["none"]
        raise MeshError(
            f"'{path}' has no triangle cells (found: {', '.join(found)}); femehl needs a "
            "2-D triangulation: remesh or export with linear triangles"
        )
    t = np.concatenate(blocks, axis=0).T.astype(np.int64)
    pts = np.asarray(m.points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] < 2:
        raise MeshError(f"'{path}' has points of shape {pts.shape}; femehl needs x, y coordinates")
    if t.size and (t.min() < 0 or t.max() >= pts.shape[0]):
        raise MeshError(f"'{path}' has triangles with node indices out of range; re-export the mesh")
    if pts.shape[1] > 2 and t.size:
        z = pts[np.unique(t), 2:]
        if np.all(np.isfinite(z)) and np.ptp(z, axis=0).max() > _RTOL_BOUNDARY * L:
            raise MeshError(
                f"'{path}' is not planar (z varies by {np.ptp(z, axis=0).max():.3g}); femehl "
                "needs a 2-D triangulation in the x-y plane"
            )
    return pts[:, :2].T.copy(), t


def _normalize(p, t, L, half, name):
    """Check a triangulation of the disk; return (p, t, half) oriented and snapped.

    ``p`` and ``t`` are the caller's own copies: they may be modified.
    """
    _check_l(L)
    L = float(L)
    where = f"mesh {name}"
    p = np.asarray(p, dtype=np.float64)
    t = np.asarray(t)
    if p.ndim != 2 or p.shape[0] != 2:
        raise MeshError(f"{where}: nodes must have shape (2, n), got {p.shape}")
    if t.ndim != 2 or t.shape[0] != 3 or t.shape[1] == 0:
        raise MeshError(
            f"{where}: no triangle cells (elements of shape {t.shape}); femehl needs a 2-D "
            "triangulation: pass a mesh of linear triangles"
        )
    if not np.issubdtype(t.dtype, np.integer):
        raise MeshError(f"{where}: element indices must be integers, got {t.dtype}")
    t = t.astype(np.int64)
    if t.min() < 0 or t.max() >= p.shape[1]:
        raise MeshError(f"{where}: element node indices out of range; re-export the mesh")

    # drop unused nodes
    used = np.unique(t)
    if used.size != p.shape[1]:
        renum = np.full(p.shape[1], -1, dtype=np.int64)
        renum[used] = np.arange(used.size)
        p = p[:, used]
        t = renum[t]
    n = p.shape[1]

    bad = ~np.all(np.isfinite(p), axis=0)
    if bad.any():
        raise MeshError(
            f"{where}: {bad.sum()} node(s) have non-finite coordinates (NaN or inf), e.g. node "
            f"{np.flatnonzero(bad)[0]}; fix the coordinates or remesh"
        )

    a = _signed_areas(p, t)
    degen = np.abs(a) <= _AREA_DEGENERATE * L * L
    if degen.any():
        e = np.flatnonzero(degen)[0]
        cx, cy = p[0, t[:, e]].mean(), p[1, t[:, e]].mean()
        raise MeshError(
            f"{where}: {degen.sum()} degenerate triangle(s) with area <= "
            f"{_AREA_DEGENERATE:g} L^2, e.g. element {e} at ({cx:.4g}, {cy:.4g}); "
            "remove zero-area triangles or remesh"
        )
    # counterclockwise by signed area (never by node order)
    neg = a < 0
    t[1, neg], t[2, neg] = t[2, neg].copy(), t[1, neg].copy()
    a = np.abs(a)

    # oriented edges: in a valid triangulation each is used once
    i = np.concatenate([t[0], t[1], t[2]])
    j = np.concatenate([t[1], t[2], t[0]])
    directed = i * n + j
    uniq, cnt = np.unique(directed, return_counts=True)
    if (cnt > 1).any():
        k = uniq[cnt > 1][0]
        raise MeshError(
            f"{where}: overlapping or folded triangles (edge {k // n}-{k % n} is used by more "
            "than one triangle in the same direction); remesh"
        )
    ne = t.shape[1]
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    undirected = lo * n + hi
    order = np.argsort(undirected, kind="stable")
    und_sorted = undirected[order]
    starts = np.r_[True, und_sorted[1:] != und_sorted[:-1]]
    first = np.flatnonzero(starts)
    counts = np.diff(np.r_[first, und_sorted.size])
    elem = np.tile(np.arange(ne), 3)[order]
    # boundary edges: used by one triangle
    bfirst = first[counts == 1]
    be_i, be_j = i[order][bfirst], j[order][bfirst]

    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    # connectivity through shared edges
    ifirst = first[counts == 2]
    g = coo_matrix((np.ones(ifirst.size), (elem[ifirst], elem[ifirst + 1])), shape=(ne, ne))
    ncomp, _ = connected_components(g, directed=False)
    if ncomp > 1:
        raise MeshError(
            f"{where}: the mesh has {ncomp} disconnected pieces; femehl needs the disk as one "
            "connected triangulation: remesh it as one piece"
        )

    bnodes = np.unique(np.concatenate([be_i, be_j]))
    deg = np.bincount(np.concatenate([be_i, be_j]), minlength=n)[bnodes]
    if (deg != 2).any():
        k = bnodes[deg != 2][0]
        raise MeshError(
            f"{where}: the boundary is not a simple closed curve (node {k} at "
            f"({p[0, k]:.4g}, {p[1, k]:.4g}) is on {deg[deg != 2][0]} boundary edges); remesh"
        )
    gb = coo_matrix((np.ones(be_i.size), (be_i, be_j)), shape=(n, n))
    _, lab = connected_components(gb, directed=False)
    nloops = np.unique(lab[bnodes]).size
    if nloops > 1:
        raise MeshError(
            f"{where}: the mesh has {nloops - 1} hole(s): its boundary has {nloops} closed "
            "loops but a disk has one; remesh the disk without holes"
        )

    # half or full
    ymin = p[1].min()
    if half is None:
        half = bool(ymin >= -_YTOL_HALF * L)
    half = bool(half)
    if half and ymin < -_YTOL_HALF * L:
        k = int((p[1] < -_YTOL_HALF * L).sum())
        raise MeshError(
            f"{where}: half=True but {k} node(s) have y < 0 (min y = {ymin:.6g}); pass "
            "half=False for a full-disk mesh, or mesh only the half disk y >= 0"
        )

    # radius
    r = np.hypot(p[0], p[1])
    R = r.max()
    rb = r[bnodes]
    on_arc = np.abs(rb - R) <= _RTOL_BOUNDARY * R
    on_line = np.abs(p[1, bnodes]) <= _RTOL_BOUNDARY * R if half else np.zeros_like(on_arc)
    off = ~(on_arc | on_line)
    if not off.any() and abs(R - L) > _RTOL_BOUNDARY * L:
        raise MeshError(
            f"{where}: mesh radius R = {R:.10g} != L = {L:.10g}; pass L={R:.10g} or scale the "
            f"mesh by L/R = {L / R:.10g}"
        )

    # covers the disk: area
    A = a.sum()
    A0 = math.pi * L * L / (2 if half else 1)
    arc = np.zeros(n, dtype=bool)
    arc[bnodes[on_arc]] = True
    chord = np.hypot(p[0, be_i] - p[0, be_j], p[1, be_i] - p[1, be_j])[arc[be_i] & arc[be_j]]
    delta = np.sum(chord**3) / (12 * L * A0)
    rtol = max(_AREA_RTOL_MIN, 2 * delta)
    rel = (A - A0) / A0
    if abs(rel) > rtol:
        hint = ""
        if not half and abs(2 * A / A0 - 1) <= max(_AREA_RTOL_MIN, 4 * delta):
            hint = " (it looks like a half disk: pass half=True)"
        raise MeshError(
            f"{where}: the mesh does not cover the {'half ' if half else ''}disk of radius L = "
            f"{L:g}: its area is {A:.6g}, not {'pi L^2 / 2' if half else 'pi L^2'} = {A0:.6g} "
            f"(relative error {rel:.3g}, tolerance {rtol:.3g}){hint}; mesh the "
            f"{'half disk r <= L, y >= 0' if half else 'disk r <= L'}"
        )
    if off.any():
        k = bnodes[off][0]
        raise MeshError(
            f"{where}: the mesh does not cover the disk: {off.sum()} boundary node(s) lie neither "
            f"on r = L{' nor on y = 0' if half else ''}, e.g. ({p[0, k]:.6g}, {p[1, k]:.6g}); "
            f"mesh the {'half disk r <= L, y >= 0' if half else 'disk r <= L'} with boundary "
            "nodes on its boundary"
        )

    # snap: arc nodes exactly onto r = L, mirror nodes exactly onto y = 0
    ka = bnodes[on_arc]
    ka = ka[np.abs(r[ka] - L) > 4 * np.finfo(float).eps * L]  # leave snapped nodes alone
    p[:, ka] *= L / r[ka]
    if half:
        p[1, bnodes[on_line]] = 0.0
        p[1, p[1] < 0] = 0.0
    return p, t, half
