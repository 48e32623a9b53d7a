"""What the documentation and the packaging files promise: the generated family pages are up to date
(and come from the code), every page the site links is in mkdocs.yml's nav, the hook reports links
to missing repository files, rl_zoo3 has hyperparameters for every id, CITATION.cff / CHANGELOG /
LICENSE are well formed. (`make docs` builds the site with `mkdocs build --strict`; CI runs it.)"""

from __future__ import annotations

import importlib.util
import logging
import re
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest
import yaml

import visuomotor_gym

REPO = Path(__file__).resolve().parent.parent
DOCS = REPO / "docs"


def _load(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def gen():
    return _load(DOCS / "gen_family_pages.py", "gen_family_pages")


@pytest.fixture(scope="module")
def generated(gen):
    return gen.pages()


def test_family_pages_are_up_to_date(generated):
    assert set(generated) == {DOCS / "families" / f"{f}.md" for f in visuomotor_gym.FAMILIES}
    stale = [p.name for p, text in generated.items() if not p.is_file() or p.read_text(encoding="utf-8") != text]
    assert not stale, f"stale family pages {stale}: run `make docs-pages` (python docs/gen_family_pages.py)"


def test_family_pages_come_from_the_code(generated):
    import gymnasium as gym

    for family, ids in visuomotor_gym.FAMILIES.items():
        text = generated[DOCS / "families" / f"{family}.md"]
        for env_id in ids:  # every registered id of the family, with its shapes
            env = gym.make(env_id)
            row = next((line for line in text.splitlines() if line.startswith(f"| `{env_id}` |")), None)
            assert row is not None, f"{family}: no row for {env_id}"
            assert f"`{env.action_space.shape}`" in row and f"`{env.observation_space.shape}`" in row, row
            env.close()
        spec = next(s for s in visuomotor_gym.ENV_SPECS if s.family == family)
        module, name = spec.entry_point.split(":")
        cls = getattr(__import__(module, fromlist=[name]), name)
        # the docstring's observation table (generated from the env's layout) is on the page
        table = [line.strip() for line in cls.__doc__.splitlines() if line.strip().startswith("| index | name |")]
        assert table and table[0] in text
        for section in ("### Action Space", "### Observation Space", "### Rewards", "### Arguments"):
            assert section in text, f"{family}: {section} missing"


def test_generator_check_mode_detects_a_stale_page(gen, generated, tmp_path, monkeypatch, capsys):
    # main()'s write/check logic on the pages generated once, written to a scratch folder
    monkeypatch.setattr(gen, "pages", lambda: {tmp_path / p.name: text for p, text in generated.items()})
    assert gen.main(["--check"]) == 1  # nothing written there yet
    assert not list(tmp_path.iterdir())
    assert gen.main([]) == 0 and gen.main(["--check"]) == 0
    page = tmp_path / "catch.md"
    page.write_text(page.read_text() + "edited by hand\n")
    assert gen.main(["--check"]) == 1
    assert "catch.md" in capsys.readouterr().err


def _nav_pages(nav) -> list[str]:
    pages = []
    for item in nav:
        if isinstance(item, str):
            pages.append(item)
        elif isinstance(item, dict):
            for value in item.values():
                pages.extend(_nav_pages(value) if isinstance(value, list) else [value])
    return pages


def test_mkdocs_nav_lists_every_page_and_every_page_exists():
    config = yaml.load((REPO / "mkdocs.yml").read_text(), Loader=yaml.UnsafeLoader)  # !!python tags
    assert config["strict"] is True
    nav = _nav_pages(config["nav"])
    for page in nav:
        assert (DOCS / page).is_file(), f"mkdocs.yml nav: {page} does not exist"
    # Markdown under a data/ folder is generated data, not a page (mkdocs.yml: not_in_nav)
    assert "data/" in config.get("not_in_nav", "")
    pages = {p.relative_to(DOCS).as_posix() for p in DOCS.rglob("*.md") if "data" not in p.relative_to(DOCS).parts}
    assert pages == set(nav), f"pages not in the nav: {sorted(pages - set(nav))}"


def test_repo_links_hook_rewrites_and_reports(caplog):
    hook = _load(DOCS / "hooks" / "repo_links.py", "repo_links_hook")
    config = {"docs_dir": str(DOCS), "config_file_path": str(REPO / "mkdocs.yml"),
              "repo_url": "https://example.org/o/r"}
    page = SimpleNamespace(file=SimpleNamespace(src_uri="reproductions/x.md"))
    text = ("[a](../../leaderboard/README.md#top) [b](eyecatch.md) [c](https://x.org/y) "
            "[d](../../no/such/file.md) [e](../../baselines/ppo/)")
    with caplog.at_level(logging.WARNING, logger="mkdocs.hooks.repo_links"):
        out = hook.on_page_markdown(text, page, config, None)
    assert "[a](https://example.org/o/r/blob/main/leaderboard/README.md#top)" in out
    assert "[b](eyecatch.md)" in out and "[c](https://x.org/y)" in out
    assert "[e](https://example.org/o/r/tree/main/baselines/ppo)" in out
    assert "[d](../../no/such/file.md)" in out
    assert any("no/such/file.md" in r.getMessage() for r in caplog.records)  # an error under --strict


def test_rl_zoo3_has_every_id():
    zoo = yaml.safe_load((REPO / "baselines" / "ppo" / "rl_zoo3.yml").read_text())
    missing = sorted(set(visuomotor_gym.ENV_IDS) - set(zoo))
    assert not missing, f"rl_zoo3.yml has no entry for {missing} (rl_zoo3 would silently use its defaults)"
    for family in ("catch", "reach", "walk", "stones", "dodge"):
        foveated = [i for i in visuomotor_gym.FAMILIES[family]
                    if not re.search(r"(Oracle|FullView|Delayed|PoorVision|Bounce|TwoBalls|Paper)", i)]
        assert foveated and all(i in zoo for i in foveated), family


def test_citation_cff():
    cff = yaml.safe_load((REPO / "CITATION.cff").read_text(encoding="utf-8"))
    assert cff["cff-version"] == "1.2.0" and cff["type"] == "software"
    assert cff["version"] == visuomotor_gym.__version__
    assert cff["license"] == "MIT"
    titles = " ".join(r["title"] for r in cff["references"])
    for word in ("Eyecatch", "Model Predictive Control with a Visuomotor System", "Bézier", "Obstacle Recognition"):
        assert word in titles
    for ref in cff["references"]:
        assert ref["type"] and ref["authors"] and all("family-names" in a for a in ref["authors"])


def test_changelog_license_and_py_typed():
    changelog = (REPO / "CHANGELOG.md").read_text(encoding="utf-8")
    assert "Keep a Changelog" in changelog and "## [Unreleased]" in changelog
    assert f"## [{visuomotor_gym.__version__}]" in changelog
    assert (REPO / "LICENSE").read_text().startswith("MIT License")
    assert (REPO / "visuomotor_gym" / "py.typed").is_file()
    pyproject = (REPO / "pyproject.toml").read_text()
    assert '"visuomotor_gym" = ["py.typed"]' in pyproject
    assert 'license = "MIT"' in pyproject


def test_install_instructions_cannot_pull_cuda_by_accident():
    import tomllib

    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    assert not any(d.lower().startswith("torch") for d in project["dependencies"]), "torch in core dependencies"
    assert any(d.startswith("torch") for d in project["optional-dependencies"]["rl"])
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Installation", 1)[1].split("\n## ", 1)[0]
    cpu = "pip install torch==2.13.0 --index-url https://download.pytorch.org/whl/cpu"
    assert cpu in section and section.index(cpu) < section.index('pip install ".[rl,viz]"')
    makefile = (REPO / "Makefile").read_text()
    assert "TORCH_INDEX ?= https://download.pytorch.org/whl/cpu" in makefile
    # the venv is given CPU torch before the extras that depend on it
    setup = makefile.split("$(STAMP): pyproject.toml Makefile", 1)[1].split("\n\n", 1)[0]
    assert setup.index("$(TORCH_SPEC)") < setup.index('".[rl,viz,dev]"')
    assert "download.pytorch.org/whl/cpu" in (DOCS / "getting-started.md").read_text(encoding="utf-8")


@pytest.mark.parametrize("doc", ["README.md", "examples/README.md", "leaderboard/README.md"])
def test_relative_links_of_repository_pages_resolve(doc):
    """The pages GitHub shows outside the site (the site's own links: mkdocs build --strict)."""
    path = REPO / doc
    links = re.findall(r"\]\(([^)\s]+)\)", path.read_text(encoding="utf-8"))
    relative = [link.split("#")[0] for link in links if not re.match(r"^[a-z]+:", link) and not link.startswith("#")]
    assert relative, f"{doc}: no relative link found (the pattern is broken)"
    missing = sorted({link for link in relative if not (path.parent / link).exists()})
    assert not missing, f"{doc}: links to missing files {missing}"
