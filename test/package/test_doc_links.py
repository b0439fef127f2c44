"""Every relative link of the README and of doc/ names a file of the repository (a moved page breaks no link)."""
import os
import re

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def pages():
    yield os.path.join(ROOT, "README.md")
    doc = os.path.join(ROOT, "doc")
    for name in sorted(os.listdir(doc)):
        if name.endswith(".md"):
            yield os.path.join(doc, name)


def test_relative_links_resolve():
    broken = []
    for page in pages():
        with open(page) as f:
            text = f.read()
        for m in re.finditer(r"\]\(([^)#\s]+)(#[^)]*)?\)", text):
            target = m.group(1)
            if re.match(r"[a-z]+://", target):
                continue
            if not os.path.exists(os.path.normpath(os.path.join(os.path.dirname(page), target))):
                broken.append(f"{os.path.relpath(page, ROOT)} -> {target}")
    assert not broken, broken


def test_readme_stays_short():
    with open(os.path.join(ROOT, "README.md")) as f:
        assert sum(1 for _ in f) <= 250, "the README is for users: move the rest to doc/"
