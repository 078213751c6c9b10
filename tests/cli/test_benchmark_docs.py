"""A benchmark's section of the docs: the command it names is the one typed, every argument kept."""

import subprocess
import sys

from ema.cli.benchmark_docs import write_section

SHOW = "from ema.cli.benchmark_docs import typed_command; print(typed_command())"


def test_the_command_a_section_names_is_the_one_typed_with_its_arguments(tmp_path):
    typed = ["--windows", "5", "--label", "two words", "--docs"]
    done = subprocess.run([sys.executable, "-c", SHOW, *typed], capture_output=True, text=True, check=True)
    command = done.stdout.strip()
    assert command.startswith("python -c ") and command.endswith("--windows 5 --label 'two words' --docs")
    page = tmp_path / "benchmarks.md"
    write_section("A figure", command, "| a | b |", page)
    write_section("A figure", command, "| c | d |", page)  # rewritten in place, not appended
    text = page.read_text()
    assert text.count("## A figure") == 1 and f"- command: `{command}`" in text and "| c | d |" in text
