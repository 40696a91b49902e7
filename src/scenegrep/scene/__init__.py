"""Scenic scene queries (seed 003): is a labeled frame an instance of a Scenic program's scene?

Pipeline: Scenic source -> IR (:mod:`scenegrep.scenic`) -> feature terms (:mod:`.resolve`) ->
dependency groups (:mod:`.dependencies`) -> Algorithm 1 over all frames (:mod:`.match`), each
group decided by closed forms (:mod:`.decide`) or the solvers (:mod:`.solvers`).

Map of the package, lowest group first: a module imports only from its own group or lower ones,
without circles (``SCENE_LAYERS`` in ``tests/test_architecture.py``). *Term language*:
:mod:`.terms` (the expression DAG of real-valued terms and random variables), :mod:`.regions` (regions and
fields over terms), :mod:`.values` and :mod:`.vectors` (what resolution computes: instances,
vectors), :mod:`.domain` (Scenic's classes and defaults), :mod:`.program` (the resolved program:
objects' feature terms, requirements). *Map geometry*: :mod:`.geometry` (regions and fields on a
road map, vectorised), :mod:`.shapes` (exact box and sector tests), :mod:`.unknown` (unknown map
layers), :mod:`.follow` and its walks ``follow_pieces``, ``follow_regions``, ``follow_inverse``,
:mod:`.clip` (lines cut by a start's domain, part by part).
*Syntax and specifier semantics*: :mod:`.expressions` (IR expressions -> values),
:mod:`.specifiers` (``new Class spec, ...``), :mod:`.lenient_boxes` (implicit requirements eased by
the tolerance), :mod:`.resolve` (statements; the :class:`~.resolve.Resolver`, the
:class:`~.context.Context` the other two evaluate in), :mod:`.needs` (map layers a program reads).
*Analysis and evaluation*: :mod:`.dependencies`, :mod:`.randoms`, :mod:`.evaluate` (terms over
rows of candidate correspondences). *Decision procedures*: :mod:`.tolerance` (per-feature
tolerances), :mod:`.decide` (closed forms, else :mod:`.solvers`). *Match driver*: :mod:`.match`
(Algorithm 1), :mod:`.query` (the API), :mod:`.explain` (witnesses), :mod:`.projection` (values of
the random variables per match), :mod:`.misses` (nearest misses), :mod:`.profiles` (named
tolerances), :mod:`.vocabulary` (program objects no searched trace has an object of the kinds of).
"""

from .tolerance import Tolerance
from .match import SceneOptions
from .query import SceneQuery, SceneResult, compile_scene, load_scene

__all__ = ["SceneOptions", "SceneQuery", "SceneResult", "Tolerance", "compile_scene", "load_scene"]
