"""The README's Python example runs as printed and prints what the README says it prints."""
import os
import re
import subprocess
import sys

import volscissors
from conftest import DATA, ROOT, shared


def test_readme_python_example_prints_what_the_readme_shows(tmp_path):
    shared("chest_cta_totalseg/ct_cropped.nii.gz")
    text = open(os.path.join(ROOT, "README.md")).read()
    section = text[text.index("\n## Python"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    printed = re.search(r"prints[^\n]*:\n```\n(.*?)```", section, re.S).group(1)
    # Run where "../shared/data" is the shared data, as from the repository root.
    work = tmp_path / "checkout"
    work.mkdir()
    (tmp_path / "shared").symlink_to(os.path.dirname(os.path.abspath(DATA)))
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(os.path.abspath(volscissors.__file__))))
    r = subprocess.run([sys.executable, "-c", code], cwd=work, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert r.stdout == printed
    assert (work / "airways.swc").stat().st_size > 0
