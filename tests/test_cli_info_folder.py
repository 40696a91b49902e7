"""``scenegrep info`` over a folder or several paths: an unreadable file is one failed line on
stderr, the others are summarised, exit code 3; a folder with no trace files is a user error."""

from scenegrep.cli.main import main
from tests.label.test_cli import folder_with_a_bad_file


def test_a_bad_file_in_a_folder_is_named_and_the_others_summarised(tmp_path, capsys):
    folder = folder_with_a_bad_file(tmp_path)
    assert main(["info", "--no-map", str(folder)]) == 3
    captured = capsys.readouterr()
    headers = [line for line in captured.out.splitlines() if not line.startswith(" ")]
    assert headers == [
        f"{folder / name}: scenegrep Parquet trace [scenegrep-parquet]" for name in ("a.parquet", "b.parquet")
    ]
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"scenegrep: failed: bad.parquet: {folder / 'bad.parquet'}: ")


def test_a_bad_file_among_several_paths_is_named_and_the_others_summarised(tmp_path, capsys):
    folder = folder_with_a_bad_file(tmp_path)
    assert main(["info", "--json", "--no-map", str(folder / "bad.parquet"), str(folder / "a.parquet")]) == 3
    captured = capsys.readouterr()
    assert len(captured.out.splitlines()) == 1 and captured.err.startswith("scenegrep: failed: bad.parquet: ")


def test_a_lone_bad_file_or_an_empty_folder_is_a_user_error(tmp_path, capsys):
    folder = folder_with_a_bad_file(tmp_path / "in")
    (tmp_path / "empty").mkdir()
    for path in (folder / "bad.parquet", tmp_path / "empty"):
        assert main(["info", str(path)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith(f"scenegrep: error: {path}: ")
