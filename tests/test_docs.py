"""The documentation's promises: its Python snippets run, its references name what exists.

Every ```python block of the README and of docs/*.md runs (each file's blocks in order, in
one fresh process, from the repository root); blocks meant to be read, not run, are
``{code-block}`` directives.  The outputs reference names every file of the run layout."""

import re
import subprocess
import sys

import pytest
from conftest import ROOT

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```python\n(.*?)^```", re.S | re.M)


@pytest.mark.parametrize("page", PAGES, ids=[p.name for p in PAGES])
def test_python_snippets_run(page, tmp_path):
    code = "\n".join(FENCE.findall(page.read_text()))
    if not code:
        pytest.skip(f"{page.name} has no Python snippets")
    script = tmp_path / "snippets.py"
    script.write_text(code)
    proc = subprocess.run([sys.executable, str(script)], cwd=ROOT, capture_output=True,
                          text=True, timeout=300, env={"OPENBLAS_NUM_THREADS": "1",
                                                       "MPLBACKEND": "Agg",
                                                       "PATH": "/usr/bin:/bin"})
    assert proc.returncode == 0, proc.stderr[-3000:]


def test_outputs_reference_names_every_file_of_the_layout():
    """Each file name RunLayout spells (its f-string fields as wildcards) is in the page."""
    layout = (ROOT / "fem_twin" / "io" / "layout.py").read_text()
    page = (ROOT / "docs" / "reference" / "outputs.md").read_text()
    names = set(re.findall(r'"([\w{}:.]+\.(?:npz|vtu|pvd|csv|png|json|nc|html|log))"', layout))
    names |= set(re.findall(r'/ "(\w+)"', layout))               # folders
    missing = []
    for name in names:
        pattern = re.escape(re.sub(r"\{[^}]*\}", "\0", name)).replace("\0", r"[\w.]+")
        if not re.search(pattern, page):
            missing.append(name)
    assert not missing, f"docs/reference/outputs.md does not name {sorted(missing)}"
