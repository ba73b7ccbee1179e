"""docs/python.md's Python blocks run (the shipped scenes named in them
loaded from the source tree's scenes/)."""

import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "python.md"
BLOCKS = re.findall(r"^```python\n(.*?)^```", PAGE.read_text(), re.S | re.M)


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_block_runs(index, monkeypatch, tmp_path, capsys):
    monkeypatch.chdir(tmp_path)
    code = re.sub(
        r'sph\.load\("(\w+)"',
        lambda m: 'sph.load(%r' % str(ROOT / "scenes" / (m.group(1) + ".yaml")),
        BLOCKS[index],
    )
    exec(compile(code, "%s block %d" % (PAGE.name, index + 1), "exec"), {})
    assert capsys.readouterr().out


def test_page_has_a_study():
    assert BLOCKS, "docs/python.md has no python block"


def test_readme_study_is_the_tested_one():
    # the README shows the same study as docs/python.md (run above)
    readme = (ROOT / "README.md").read_text()
    shown = re.findall(r"^```python\n(.*?)^```", readme, re.S | re.M)
    assert shown and shown[0] == BLOCKS[0]
