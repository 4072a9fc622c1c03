"""The settings tables in docs/algorithms.md are generated from the config dataclasses: keep them current."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_settings_tables_are_up_to_date():
    done = subprocess.run(
        [sys.executable, str(ROOT / "docs" / "gen_settings.py"), "--check"], capture_output=True, text=True
    )
    assert done.returncode == 0, (
        f"run `python docs/gen_settings.py` to refresh docs/algorithms.md\n{done.stdout}{done.stderr}"
    )
