"""Scene files cannot make the reader hang, eat memory or leak a traceback."""

from __future__ import annotations

import pytest

from affordplan.app.scene_file import load_scene
from affordplan.errors import InputError

VALID = "object: cube\nstart: {xy: [0.5, 0.0]}\ngoal: {xy: [0.6, 0.0]}\n"


def _alias_bomb(levels: int = 9) -> str:
    names = [chr(97 + i) for i in range(levels)]
    lines = [f"  {names[0]}: &{names[0]} [x, x]"]
    lines += [f"  {b}: &{b} [*{a}, *{a}, *{a}, *{a}]" for a, b in zip(names, names[1:])]
    return "description:\n" + "\n".join(lines) + "\n" + VALID


def test_a_yaml_alias_bomb_is_refused_at_once(tmp_path):
    path = tmp_path / "bomb.yaml"
    path.write_text(_alias_bomb())
    with pytest.raises(InputError, match="aliases") as info:  # refused from the event stream: nothing is expanded
        load_scene(path)
    assert len(str(info.value)) < 300


@pytest.mark.parametrize("text, words", [
    ("[" * 5000 + "]" * 5000, "deeper"),
    ("object: cube\nstart: {xy: [0.5, " + "1" * 400 + "]}\ngoal: {xy: [0.6, 0.0]}\n", "400 digits"),
])
def test_deep_nesting_and_huge_numbers_are_clear_errors(tmp_path, text, words):
    path = tmp_path / "s.yaml"
    path.write_text(text)
    with pytest.raises(InputError, match=words):
        load_scene(path)


def test_json_nesting_latin1_and_folders(tmp_path):
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100000 + "]" * 100000)
    with pytest.raises(InputError, match="nested"):
        load_scene(deep)
    latin = tmp_path / "latin.yaml"
    latin.write_bytes(("description: caf\u00e9\n" + VALID).encode("latin-1"))
    with pytest.raises(InputError, match="UTF-8"):
        load_scene(latin)
    folder = tmp_path / "scene.json"
    folder.mkdir()
    with pytest.raises(InputError, match="is a folder"):
        load_scene(folder)
    ok = tmp_path / "ok.yaml"
    ok.write_text(VALID)
    assert load_scene(ok).object == "cube"
