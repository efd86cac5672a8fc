"""Shared helpers of the Python module's tests: the C++ routes the module is compared with."""

import json
import os
import subprocess

import pytest

SOURCE_DIR = os.environ["AIRTWIN_SOURCE_DIR"]

# Both front ends build the physical twin by default (docs/twin.md). Most comparisons run in the
# mirror (the model's air, eq. (8) drag; MIRROR on the CLI, MIRROR_KW in the module), which is
# quick, or in the CFD's air with eq. (8) drag; both take the default field model.
MIRROR = ("--air", "model", "--drag", "eq8")
MIRROR_KW = {"air": "model", "drag": "eq8"}
CFD_EQ8_KW = {"air": "cfd", "drag": "eq8"}
CONSTRUCTED = os.path.join(SOURCE_DIR, "models/data/constructed_field_table.csv")
CFD_AIR_EQ8 = ("--air", "cfd", "--drag", "eq8")


def run_cli(*args):
    """Runs the `airtwin` CLI; returns (exit status, stdout, stderr)."""
    done = subprocess.run([os.environ["AIRTWIN_BINARY"], *map(str, args)], capture_output=True,
                          text=True, check=False)
    return done.returncode, done.stdout, done.stderr


def cli_error(*args):
    """The one stderr line of a CLI run that fails with status 1, without 'airtwin: error: '."""
    status, _, stderr = run_cli(*args)
    assert status == 1, stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("airtwin: error: "), stderr
    return lines[0][len("airtwin: error: "):]


def expect_cli_error(call, *cli_args):
    """call() raises ValueError with the line the CLI prints for cli_args."""
    with pytest.raises(ValueError) as raised:
        call()
    assert str(raised.value) == cli_error(*cli_args)
    return str(raised.value)


def assert_same_run(result, out):
    """A RunResult is the `airtwin run` written to `out`: every frame (log.csv), command
    (nozzle.csv) and figure of summary.json but the wall-clock times of decisions and frames."""
    assert result.log_csv() == (out / "log.csv").read_text()
    assert result.nozzle_csv() == (out / "nozzle.csv").read_text()
    summary, cli = json.loads(result.summary_json()), json.loads((out / "summary.json").read_text())
    for figures in (summary, cli):
        figures.pop("decision_ms")
        figures.get("vision", {}).pop("frame_ms", None)
    assert summary == cli
    return cli


@pytest.fixture
def source_dir():
    return SOURCE_DIR
