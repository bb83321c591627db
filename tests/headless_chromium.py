"""Headless Chromium for the browser tests (the editor's and Origami Simulator's).

Debian's ``chromium`` package (``KINEGAMI_CHROMIUM`` or /usr/bin/chromium) driven by Playwright
from PyPI with software WebGL (SwiftShader); Playwright's own browser download is not used. A
test module asks :func:`require` for what it needs: the tests skip when something is missing,
and fail instead when ``KINEGAMI_REQUIRE_BROWSER`` is set (CI).
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
from pathlib import Path

import pytest

#: Chromium's flags: headless, software WebGL, nothing phoning home.
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]

#: What to install for a missing module.
_INSTALL = {"playwright": "pip install '.[dev]'", "viser": "pip install '.[gui]'"}


def chromium_path() -> Path:
    """The Chromium executable the tests run."""
    return Path(os.environ.get("KINEGAMI_CHROMIUM", "/usr/bin/chromium"))


def missing(*modules: str) -> str | None:
    """Why the browser tests cannot run (playwright, ``modules`` or chromium absent), or None."""
    for module in ("playwright", *modules):
        if importlib.util.find_spec(module) is None:
            return f"{module} is not installed ({_INSTALL.get(module, f'pip install {module}')})"
    if not chromium_path().is_file():
        return f"no chromium at {chromium_path()} (apt-get install chromium, or KINEGAMI_CHROMIUM)"
    return None


def require(reason: str | None) -> None:
    """Skip the test for ``reason`` (None: nothing is missing), or fail under
    KINEGAMI_REQUIRE_BROWSER."""
    if reason is None:
        return
    if os.environ.get("KINEGAMI_REQUIRE_BROWSER"):
        pytest.fail(f"browser tests required but {reason}")
    pytest.skip(reason)


def launch(playwright, chromium: Path | None = None):
    """A headless Chromium browser of a started Playwright."""
    return playwright.chromium.launch(
        executable_path=str(chromium or chromium_path()), args=CHROMIUM_ARGS
    )


@contextlib.contextmanager
def browser():
    """Playwright and one headless Chromium, for a ``with`` block."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        chromium = launch(playwright)
        try:
            yield chromium
        finally:
            chromium.close()
