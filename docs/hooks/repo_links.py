"""MkDocs hook: links from a page to repository files outside ``docs/`` (``../../leaderboard/README.md``,
``../../baselines/ppo/rl_zoo3.yml``) become links to the file on the repository host, so a page reads
the same on GitHub and on the site. A link to a file that does not exist is reported as a warning,
which ``mkdocs build --strict`` turns into an error (link checking for what MkDocs itself cannot see).
"""

from __future__ import annotations

import logging
import posixpath
import re
from pathlib import Path

log = logging.getLogger("mkdocs.hooks.repo_links")
LINK = re.compile(r"(\]\()([^)\s#]+)(#[^)\s]*)?(\))")
BRANCH = "main"


def on_page_markdown(markdown, page, config, files):
    docs = Path(config["docs_dir"]).resolve()
    root = Path(config["config_file_path"]).resolve().parent
    repo = (config.get("repo_url") or "").rstrip("/")
    page_dir = (docs / page.file.src_uri).parent

    def rewrite(m):
        target = m.group(2)
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("/"):
            return m.group(0)  # absolute URL or site-absolute path: MkDocs' own validation
        path = Path(posixpath.normpath((page_dir / target).as_posix()))
        try:
            path.relative_to(docs)
            return m.group(0)  # inside docs/: MkDocs validates it
        except ValueError:
            pass
        try:
            rel = path.relative_to(root).as_posix()
        except ValueError:
            log.warning("%s: link %r points outside the repository", page.file.src_uri, target)
            return m.group(0)
        if not path.exists():
            log.warning("%s: link %r: no such file in the repository (%s)", page.file.src_uri, target, rel)
            return m.group(0)
        kind = "tree" if path.is_dir() else "blob"
        return f"{m.group(1)}{repo}/{kind}/{BRANCH}/{rel}{m.group(3) or ''}{m.group(4)}"

    return LINK.sub(rewrite, markdown)
