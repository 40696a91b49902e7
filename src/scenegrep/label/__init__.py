"""Behaviour labels derived from tracks and the road map (``scenegrep label``).

Pipeline: :mod:`.tracks` (segments, windows) → :mod:`.evidence` (kinematics and map relations)
→ :mod:`.rules` (confidences per behaviour, thresholds from :mod:`.config`) → :mod:`.labeller`
(label sets) → :mod:`.statistics` (per-class summaries).
"""

from .config import DEFAULT_CONFIG, LabelConfig, load_config
from .labeller import LABELLER_VERSION, Labelling, label_trace
from .rules import SCENIC_LABELS, VOCABULARY

__all__ = [
    "DEFAULT_CONFIG",
    "LABELLER_VERSION",
    "SCENIC_LABELS",
    "VOCABULARY",
    "LabelConfig",
    "Labelling",
    "label_trace",
    "load_config",
]
