"""The examples of docs/cli.md, run as the page shows them, and the page against the parser.

Every ``$ ...`` line of a ``console`` block (and every line of an ``sh`` block) of docs/cli.md is a command.
They run in the page's order in one empty folder that sees the checkout's ``examples/``, ``tests/`` and
``sumo_networks/`` (the page's commands run from the checkout), ``cosim`` in this process
(:func:`_cli.cosim_cli`), anything else through bash. A command must exit as the page says: 2 where its
shown output is a ``cosim: error:`` line, the number an ``$ echo $?`` line shows, else 0. The first line of
the shown output must be the first line the command printed, numbers aside (the rest need not match: wall
times, dates, sizes, the last digits of sums and the elided ``...`` parts differ).

Files the page reads but no example writes are made first (:data:`MADE_FOR_THE_PAGE`), and a log the page
names with a time stamp (``Wrote the log runs/paper-double-tee-20261201-234845.mcap``) is the one the run
wrote, renamed to that name, so that the commands after it find it. A few examples take minutes or need a
signal sent by hand: :data:`NOT_RUN` lists them, each with the test that covers it instead; they are
reported as skipped, with that reason.
"""
from __future__ import annotations

import argparse
import re
import shlex
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest
from _cli import REPO, CliResult, cosim_cli

from cosim.cli.app import build_parser

DOC = REPO / "docs" / "cli.md"

#: Commands of the page not run here (the command as written, without its comment) -> why, and what covers it.
NOT_RUN = {
    "cosim run paper-double-tee --out full.mcap":
        "needs a disk that fills during the run; a real file-size limit on a real run: "
        "tests/robustness/test_errors.py::test_a_log_that_cannot_be_finished_says_up_to_when_it_can_be_read",
    "cosim run long.toml --out long.mcap":
        "needs a SIGTERM sent by hand 25 s into a 10000 s run; real signals on real runs: "
        "tests/integration/test_logging_cli.py, tests/robustness/test_signals.py",
    "echo $?": "the exit status of the interrupted run above (not run)",
    'cosim info long.mcap | grep -E "Simulated|Status|Truncated"': "reads the interrupted run's log (not run)",
    "cosim validate --quick":
        "about a minute on 2 cores; its cases run in tests/verification/test_cases.py (the same registry), "
        "the command's report in tests/integration/test_validation.py",
    "cosim study examples/studies/volumes.toml --workers 2":
        "18 runs of 5 simulated minutes; studies on short durations: tests/integration/test_studies.py and "
        "tests/integration/test_worked_examples.py",
    "cosim dataset examples/datasets/healthy-damaged.toml":
        "72 runs, about 95 s; a short dataset: tests/integration/test_dataset.py",
}

#: The checkout's folders the page's commands read (as they would from the checkout).
INPUTS = ("examples", "tests", "sumo_networks")


@dataclass(frozen=True)
class Example:
    """One command of the page: where it is, what it is, and the output the page shows after it."""

    line: int
    command: str
    shown: tuple[str, ...]

    @property
    def expected_status(self) -> int:
        return 2 if any(line.startswith("cosim: error:") for line in self.shown) else 0


def _without_comment(command: str) -> str:
    """The command as written, without a trailing ``# comment`` (a ``#`` outside quotes after a space)."""
    quote = None
    for i, char in enumerate(command):
        if quote:
            quote = None if char == quote else quote
        elif char in "'\"":
            quote = char
        elif char == "#" and i > 0 and command[i - 1].isspace():
            return command[:i].rstrip()
    return command.rstrip()


def page_examples(text: str) -> list[Example]:
    """The page's commands in order: ``$ `` lines of ``console`` blocks, every line of ``sh`` blocks."""
    examples: list[Example] = []
    block: str | None = None
    current: tuple[int, str] | None = None
    shown: list[str] = []

    def close() -> None:
        nonlocal current, shown
        if current is not None:
            examples.append(Example(current[0], current[1], tuple(shown)))
        current, shown = None, []

    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith("```"):
            if block is None:
                block = line[3:].strip()
            else:
                close()
                block = None
            continue
        if block == "console":
            if line.startswith("$ "):
                close()
                current = (number, _without_comment(line[2:]))
            elif current is not None:
                shown.append(line)
        elif block == "sh" and line.strip() and not line.lstrip().startswith("#"):
            examples.append(Example(number, _without_comment(line.strip()), ()))
    return examples


EXAMPLES = page_examples(DOC.read_text(encoding="utf-8"))
TO_RUN = [e for e in EXAMPLES if e.command not in NOT_RUN]


def _huge_scenario(folder: Path) -> None:
    """A bridge of 100,000,000 elements: past the DOF limit, so refused before anything is built."""
    text = (REPO / "cosim" / "scenarios" / "paper-double-tee.toml").read_text(encoding="utf-8")
    text = re.sub(r"(?m)^name = .*\n", "", text, count=1)  # named after its file, as the page shows
    text = re.sub(r"(?m)^elements_per_span = \d+", "elements_per_span = 100000000", text)
    (folder / "huge.toml").write_text(text, encoding="utf-8")


def _not_mcap(folder: Path) -> None:
    (folder / "notes.txt.mcap").write_text("Meeting notes, not a log.\n", encoding="utf-8")


def _tampered(folder: Path) -> None:
    """The paper case's log (written by an example above) with one byte of its embedded scenario changed."""
    log = folder / "runs" / "paper-double-tee-20261201-234845.mcap"
    raw = bytearray(log.read_bytes())
    scenario = (REPO / "cosim" / "scenarios" / "paper-double-tee.toml").read_bytes()
    at = raw.find(scenario)  # attachments are stored uncompressed, once
    assert at > 0
    raw[at] ^= 0x20
    (folder / "tampered.mcap").write_bytes(bytes(raw))


#: Files the page reads that no example of it writes -> how each is made.
MADE_FOR_THE_PAGE = {"huge.toml": _huge_scenario, "notes.txt.mcap": _not_mcap, "tampered.mcap": _tampered}

WROTE_LOG = re.compile(r"^Wrote the log (\S+) \(", re.MULTILINE)


def _run(example: Example, folder: Path, previous: int) -> CliResult:
    """Run one command of the page in ``folder``; ``previous`` is the last exit status (for ``echo $?``)."""
    for name, make in MADE_FOR_THE_PAGE.items():
        if name in example.command and not (folder / name).exists():
            make(folder)
    cosim_part, _, rest = example.command.partition(" | ")
    if cosim_part.startswith("cosim "):
        result = cosim_cli(*shlex.split(cosim_part)[1:], cwd=folder)
        if rest and result.returncode == 0:  # the rest of the pipeline on what cosim printed
            piped = subprocess.run(["bash", "-c", rest], input=result.stdout, capture_output=True, text=True,
                                   cwd=folder, timeout=60)
            result = CliResult(piped.returncode, piped.stdout, result.stderr + piped.stderr)
        shown_log, written = WROTE_LOG.search("\n".join(example.shown)), WROTE_LOG.search(result.stdout)
        if shown_log and written and shown_log[1] != written[1]:
            (folder / written[1]).rename(folder / shown_log[1])
        return result
    if example.command == "echo $?":
        return CliResult(0, f"{previous}\n", "")
    done = subprocess.run(["bash", "-c", example.command], capture_output=True, text=True, cwd=folder, timeout=60)
    return CliResult(done.returncode, done.stdout, done.stderr)


def _digits_masked(line: str) -> str:
    """The line with every number replaced (sizes, times and counts of another run differ)."""
    return re.sub(r"\d+(\.\d+)?", "#", line)


@pytest.fixture(scope="module")
def page_run(tmp_path_factory: pytest.TempPathFactory) -> dict[int, CliResult]:
    """Every example of the page that is run, in order, in one folder: line -> what it did."""
    folder = tmp_path_factory.mktemp("cli-page")
    for name in INPUTS:
        (folder / name).symlink_to(REPO / name, target_is_directory=True)
    results: dict[int, CliResult] = {}
    previous = 0
    for example in TO_RUN:
        results[example.line] = result = _run(example, folder, previous)
        previous = result.returncode
    shutil.rmtree(folder, ignore_errors=True)
    return results


@pytest.mark.parametrize("example", TO_RUN, ids=[f"line{e.line}:{e.command[:60]}" for e in TO_RUN])
def test_the_example_exits_and_begins_as_the_page_shows(example: Example, page_run: dict[int, CliResult]) -> None:
    result = page_run[example.line]
    expected = int(example.shown[0]) if example.command == "echo $?" else example.expected_status
    assert result.returncode == expected, f"docs/cli.md:{example.line}: {example.command}\n{result.stderr}"
    printed = (result.stdout + result.stderr).splitlines()
    shown = [line for line in example.shown if line.strip()]
    if shown and shown[0] != "...":
        assert printed and _digits_masked(printed[0]) == _digits_masked(shown[0]), \
            f"docs/cli.md:{example.line}: {example.command}"


@pytest.mark.parametrize("command", list(NOT_RUN), ids=list(NOT_RUN))
def test_examples_not_run_here_are_listed_with_the_test_that_covers_them(command: str) -> None:
    assert command in [e.command for e in EXAMPLES], f"{command!r} is no longer in docs/cli.md: remove it"
    pytest.skip(f"docs/cli.md example not run: {NOT_RUN[command]}")


def test_the_page_has_every_command_and_every_option() -> None:
    parser = build_parser()
    text = DOC.read_text(encoding="utf-8")
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    missing = []
    for name, sub in commands.choices.items():
        section = text.split(f"## `cosim {name}`", 1)
        if len(section) == 1:
            missing.append(f"cosim {name}: no section")
            continue
        body = section[1].split("\n## ", 1)[0]
        if f"$ cosim {name}" not in body and f"\ncosim {name}" not in body:
            missing.append(f"cosim {name}: no example")
        for action in sub._actions:
            for option in action.option_strings:
                if option not in ("-h", "--help") and option not in body:
                    missing.append(f"cosim {name}: {option}")
    assert not missing, "docs/cli.md lacks: " + ", ".join(missing)
