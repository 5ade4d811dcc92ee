"""docs/api.md is generated from the docstrings (docs/gen_api.py) and must say what today's code says."""

import runpy
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_api_reference_is_current_and_documents_every_module():
    gen = runpy.run_path(str(ROOT / "docs" / "gen_api.py"))
    text = gen["generate"]()
    assert "not documented" not in text
    assert text == (ROOT / "docs" / "api.md").read_text(encoding="utf-8"), "run python docs/gen_api.py"
