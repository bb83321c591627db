"""Every editor test gets its own data folder (``XDG_DATA_HOME``), so that autosaves never go
to the real one of the user running the tests; ``view`` is the editor view of the module's own
``server`` fixture (each module serves its design); ``browser`` is headless Chromium for the
browser tests (a module that needs another one defines its own)."""

from __future__ import annotations

import pytest


@pytest.fixture(autouse=True)
def data_home(tmp_path_factory, monkeypatch):
    """The data folder's parent: ``$XDG_DATA_HOME`` for this test (a fresh folder)."""
    path = tmp_path_factory.mktemp("data")
    monkeypatch.setenv("XDG_DATA_HOME", str(path))
    return path


@pytest.fixture
def view(server):
    """An EditorView on the module's ``server`` (no browser: the server's own scene)."""
    view = server.new_view(server.server)
    yield view
    view.close()


@pytest.fixture(scope="module")
def browser():
    """Headless Chromium (Playwright; tests/headless_chromium.py), one per module; skips when
    playwright, viser or chromium is missing."""
    import headless_chromium

    headless_chromium.require(headless_chromium.missing("viser"))
    with headless_chromium.browser() as chromium:
        yield chromium
