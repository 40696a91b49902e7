"""A dataset directory the catalog cannot make is a one-line user error naming it, not a traceback
(the CLI refuses the names it can tell beforehand: tests/cli/test_ingest_output.py)."""

from __future__ import annotations

import pytest

from scenegrep.dataset.catalog import Catalog
from scenegrep.errors import UserError


def test_a_directory_below_a_file_is_a_user_error(tmp_path):
    plain = tmp_path / "plain"
    plain.write_text("x")
    with pytest.raises(UserError, match="cannot make the dataset directory: Not a directory") as caught:
        Catalog(plain / "ds", create=True)
    assert str(plain / "ds") in str(caught.value)
