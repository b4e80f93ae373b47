"""Discretizations: where the unknowns live and the operators of the Reynolds step.

A method (``femehl.solve(..., method=NAME)``) is a discretization class registered in
:data:`METHODS` with :func:`register_method`; the stepper (:mod:`femehl.solver.stepper`) is
the same for all of them.  Registered here:

``"fe"`` (:mod:`.fe_disk`)
    P1 pressure on a triangulated disk (scikit-fem), film on element centroids.
``"fd"`` (:mod:`.fd_polar`)
    The paper's polar finite differences (Eqs. 13-26), the reference.
``"line"`` (:mod:`.fe_line`)
    Line contact: P1 pressure on a 1-D mesh of [-L, L].

What a discretization provides (all built once, from the scene):

* ``method``, ``scene``, ``info`` (dict), ``default_linear_solver``;
* ``n`` pressure unknowns, ``free_index`` (their places in the nodal vector),
  ``expand(p)`` (nodal pressure), ``nodes`` (nodal positions, (N, 2));
* ``film_points`` ((nf, 2): where ``d`` and ``w`` live), ``shape`` (the indenter's
  gap there), ``gap(points)``, ``load_weights`` (``load = g . p``, whole plane);
* ``poiseuille(d, m, dm_dd)`` (sparse n x n: the discrete ``-div(m grad p)`` on the
  test rows), ``couette()`` and ``squeeze()`` (sparse n x nf: ``-d/dx`` and the mass of
  a film-point field, as in the weak form), see :mod:`femehl.solver.terms`;
* for substrates: ``average()`` (sparse nf x n), ``pressure_rows(points)`` (sparse),
  ``boussinesq()`` (dense nf x n) and ``boussinesq_rows(points)`` (dense); optionally
  ``radial_kernel(kernel)`` / ``radial_kernel_rows(kernel, points)`` (a radial kernel
  ``a/r - R(r)``, R smooth: an elastic layer; "fe" and "fd" have them);
* for the film check: ``node_average`` (sparse N x nf, or None when the film points are
  the nodes) and ``node_shape``;
* for results and writers: ``pressure_at``, ``film_at``, ``deflection_at``,
  ``vtk_geometry()``, ``centreline()``.
"""

from __future__ import annotations

from femehl.registry import Registry

__all__ = ["METHODS", "register_method", "method_class"]

#: name -> discretization class
METHODS = Registry("method", stamp="method")
#: class decorator adding a discretization to :data:`METHODS`: ``@register_method("fe")``
register_method = METHODS.register


def _load():
    from femehl.discretize import fd_polar, fe_disk, fe_line  # noqa: F401  (they register themselves)


def method_class(name):
    _load()
    return METHODS.get(name)
