"""Scenic scene queries (seed 003): is a labeled frame an instance of a Scenic program's scene?

Pipeline: Scenic source -> IR (:mod:`scenegrep.scenic`) -> feature terms
(:mod:`.resolve`) -> dependency groups (:mod:`.dependencies`) -> Algorithm 1
over all frames (:mod:`.match`), each group decided by closed forms
(:mod:`.decide`) or the solvers (:mod:`.solvers`).
"""

from .tolerance import Tolerance
from .match import SceneOptions
from .query import SceneQuery, SceneResult, compile_scene, load_scene

__all__ = ["SceneOptions", "SceneQuery", "SceneResult", "Tolerance", "compile_scene", "load_scene"]
