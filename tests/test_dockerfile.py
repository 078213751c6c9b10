"""The image's build-time Python lines run as written: a rename in ema must not leave the image unbuildable."""

import re
import subprocess
import sys
from pathlib import Path

DOCKERFILE = Path(__file__).resolve().parents[1] / "Dockerfile"


def test_every_python_line_of_the_image_build_runs():
    lines = re.findall(r'^RUN python -c "(.+)"$', DOCKERFILE.read_text(), flags=re.MULTILINE)
    assert lines  # the warm-up at least
    for code in lines:
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, f"{code}\n{done.stderr[-2000:]}"
