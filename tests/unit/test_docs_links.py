"""The docs' cross-references resolve: every ``docs/<name>.md`` named in the README, the docs,
the package, the scripts and the tests, and every ``(X.md)`` link of a Markdown file, is a
file of the repository; and every section a ``docs/<name>.md``, "Heading" reference quotes is a
heading or a bold paragraph title (``**Title.**``) of that file."""

import os
import re

from helpers import REPO_ROOT

FOLDERS = ("docs", "petsc_rod", "scripts", "tests")
DOC_NAME = re.compile(r"\bdocs/([\w.-]+\.md)")
MARKDOWN_LINK = re.compile(r"\]\(([\w./-]+\.md)(#[\w-]+)?\)")
# `docs/<name>.md`, "A heading" (a quoted section of that file; the quote may wrap a line)
SECTION = re.compile(r"docs/([\w.-]+\.md)`?,\s+\"([^\"]+)\"")


def sources():
    """{path relative to the repository: text} of the README and every .md, .py and .sh
    file under FOLDERS."""
    found = {"README.md": None}
    for top in FOLDERS:
        for folder, _, files in os.walk(os.path.join(REPO_ROOT, top)):
            for name in files:
                if name.endswith((".md", ".py", ".sh")):
                    found[os.path.relpath(os.path.join(folder, name), REPO_ROOT)] = None
    for path in found:
        with open(os.path.join(REPO_ROOT, path), encoding="utf-8") as stream:
            found[path] = stream.read()
    return found


NUMBERING = re.compile(r"^(\d+[a-z]?\.|[A-Z]\.)\s+")     # "2a. ", "B. "
BOLD_TITLE = re.compile(r"\*\*([^*]+)\*\*")


def titles(name):
    """The headings of docs/name (without their #'s and numbering) and its bold paragraph
    titles."""
    with open(os.path.join(REPO_ROOT, "docs", name), encoding="utf-8") as stream:
        text = stream.read()
    found = [NUMBERING.sub("", line.lstrip("#").strip())
             for line in text.splitlines() if line.startswith("#")]
    return found + BOLD_TITLE.findall(text)


def test_every_named_doc_exists():
    missing = []
    for path, text in sources().items():
        for name in DOC_NAME.findall(text):
            if not os.path.isfile(os.path.join(REPO_ROOT, "docs", name)):
                missing.append(f"{path}: docs/{name}")
        if path.endswith(".md"):
            for target, _ in MARKDOWN_LINK.findall(text):
                here = os.path.dirname(os.path.join(REPO_ROOT, path))
                if not os.path.isfile(os.path.normpath(os.path.join(here, target))):
                    missing.append(f"{path}: ({target})")
    assert not missing, missing


def test_every_quoted_section_is_a_heading():
    """A quoted section names the start of a heading or bold title of its file (the quote
    may stop before the title does, e.g. at a colon)."""
    missing = []
    for path, text in sources().items():
        # comments wrap their quotes across lines with the comment's marker
        flat = re.sub(r"\s*\n\s*(#\s*)?", " ", text)
        for name, section in SECTION.findall(flat):
            if not os.path.isfile(os.path.join(REPO_ROOT, "docs", name)):
                continue                               # the other test says so
            if not any(title.startswith(section.rstrip(".,;:")) for title in titles(name)):
                missing.append(f"{path}: docs/{name}, \"{section}\"")
    assert not missing, missing
