"""The stderr report of the user's choice for unknown map layers."""

from scenegrep.model.layers import UnknownLayers


def test_no_choice_reports_nothing():
    assert UnknownLayers().report() is None


def test_the_report_counts_decisions_per_layer():
    choice = UnknownLayers("strict")
    choice.count("shoulder", 2)
    choice.count("crossing", 3)
    choice.count("sidewalk", 0)
    assert choice.report() == (
        "--unknown-layers strict: unknown map layers taken as empty; decisions affected: crossing 3, shoulder 2"
    )
