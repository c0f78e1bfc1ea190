"""`rigedit info` lists a rig's morph targets (shapes), read back from its rig folder."""
import rigedit
from morph_builders import quadruped_with_targets
from rigedit.cli.main import main


def _info(path, capsys):
    assert main(["info", str(path)]) == 0
    return dict(line.split(": ", 1) for line in capsys.readouterr().out.splitlines())


def test_info_lists_the_shapes(tmp_path, capsys):
    rigedit.save_rig(quadruped_with_targets(), tmp_path / "q")
    assert _info(tmp_path / "q", capsys)["shapes"] == "bulge squash"


def test_info_says_when_there_are_none(tmp_path, capsys):
    rigedit.save_rig(rigedit.load_rig("quadruped"), tmp_path / "q")
    assert _info(tmp_path / "q", capsys)["shapes"] == "-"
