"""MkDocs hook (mkdocs.yml ``hooks:``): put the repository's benchmark records into the site, so that the pages'
links to them work there as they do in the repository.

The pages link to ``../benchmarks/*.md`` (the records each result cites) and to an experiment file under
``../src``, outside ``docs/``, where MkDocs finds no page and ``--strict`` fails. This hook adds those files to
the site (``benchmarks/`` and the experiment configs keep their repository paths under the site's root) and
rewrites each relative link by the repository's layout: a link is resolved from the linking file's place in
the repository, then written relative to that file's place in the site (``docs/X`` is the site's ``X``). A
link to a file that is neither a page nor one of these is left as it is, for MkDocs to report.
"""

from __future__ import annotations

import posixpath
import re
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parent.parent
EXTRA = [("benchmarks", ("*.md", "*.png", "*.svg", "*.toml", "*.csv")), ("src/pamdp/experiments/configs", ("*.toml",))]
LINK = re.compile(r"(\]\()([^)\s#]+)(#[^)\s]*)?(\))")


def _repo_path(site_path: str) -> str:
    """The repository path of a file at ``site_path`` in the site."""
    return site_path if site_path.startswith(tuple(f"{d}/" for d, _ in EXTRA)) else f"docs/{site_path}"


def _site_path(repo_path: str) -> str:
    return repo_path[len("docs/") :] if repo_path.startswith("docs/") else repo_path


def on_files(files, config):
    for folder, patterns in EXTRA:
        for pattern in patterns:
            for path in sorted((ROOT / folder).rglob(pattern)):
                uri = path.relative_to(ROOT).as_posix()
                if files.get_file_from_path(uri) is None:
                    files.append(File(uri, str(ROOT), config["site_dir"], config["use_directory_urls"]))
    return files


def on_page_markdown(markdown, page, config, files):
    here = posixpath.dirname(page.file.src_uri)
    repo_here = posixpath.dirname(_repo_path(page.file.src_uri))

    def rewrite(m):
        url = m.group(2)
        if "://" in url or url.startswith(("/", "mailto:")):
            return m.group(0)
        target = _site_path(posixpath.normpath(posixpath.join(repo_here, url)))
        if files.get_file_from_path(target) is None:
            return m.group(0)
        new = posixpath.relpath(target, here or ".")
        return f"{m.group(1)}{new}{m.group(3) or ''}{m.group(4)}"

    return LINK.sub(rewrite, markdown)
