"""A command line argparse refuses is one line on stderr naming the command and where its
usage is, exit 2 (argparse's own print the usage first: five lines for ``rigedit compress``)."""
import pytest

from rigedit.cli.main import main


@pytest.mark.parametrize("argv, command, says", [
    (["compress"], "rigedit compress", "required: rig, -o/--output"),
    (["nonsense"], "rigedit", "invalid choice: 'nonsense'"),
    (["compress", "humanoid", "-o", "x.rgc", "--max-error", "abc"], "rigedit compress",
     "invalid float value: 'abc'"),
    (["batch", "retarget"], "rigedit batch retarget", "required: MOTIONS, --to"),
])
def test_a_refused_command_line_is_one_line(argv, command, says, capsys):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    out, err = capsys.readouterr()
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"{command}: error: ") and says in lines[0]
    assert lines[0].endswith(f"(see {command} --help)")
