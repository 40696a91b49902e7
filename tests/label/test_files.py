"""label.files.FolderLabelling: what ``scenegrep label`` writes into its folder."""

from __future__ import annotations

import pytest

from scenegrep import readers
from scenegrep.errors import UserError
from scenegrep.label import load_config
from scenegrep.label.files import FolderLabelling
from tests.conftest import REPO

TRACE = str(REPO / "examples" / "sample" / "fig1_lane_change-000.parquet")


def test_a_name_written_twice_gets_a_suffix_and_both_are_counted(tmp_path):
    labelling = FolderLabelling(tmp_path / "out", load_config(None))
    seen = []
    labelling.label_input(TRACE, lambda: seen.append(1))
    labelling.label_input(TRACE, lambda: seen.append(1))
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "fig1_lane_change-000-2.parquet",
        "fig1_lane_change-000.parquet",
    ]
    assert len(seen) == 2
    first, second = (
        readers.read_trace(tmp_path / "out" / n) for n in sorted(p.name for p in (tmp_path / "out").iterdir())
    )
    assert first.behaviours is not None and second.n_frames == first.n_frames


@pytest.mark.parametrize("confidence", [-0.1, 1.5, float("nan")])
def test_min_confidence_outside_0_1_is_a_user_error(tmp_path, confidence):
    with pytest.raises(UserError, match="--min-confidence must be between 0 and 1"):
        FolderLabelling(tmp_path / "out", load_config(None), min_confidence=confidence)
    assert not (tmp_path / "out").exists()
