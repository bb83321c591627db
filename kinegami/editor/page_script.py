"""Scripts the editor runs in a browser tab, beside viser's own page (docs/editor.md).

viser serves a fixed page and has no hook for the editor's own browser code; it does have a
message that runs JavaScript in a tab (the one ``gui.add_plotly`` sends plotly.js with).
:func:`run_javascript` sends such a message to one tab (a viser ClientHandle) or every tab (a
ViserServer); it is the editor's one way to put code in the page: the warning before closing
a tab with unsaved changes (:func:`unsaved_changes_script`) uses it, and so can keyboard
shortcuts. Scripts must be idempotent (a tab that reconnects gets them again).
"""

from __future__ import annotations

import json
from typing import Any

__all__ = ["run_javascript", "unsaved_changes_script"]

#: Installed once per page: warn before the tab closes or reloads while ``window.__kinegami
#: .unsaved`` is true (the browser shows its own "leave site?" dialog).
_GUARD = """
const k = (window.__kinegami = window.__kinegami || {});
if (!k.unloadGuard) {
  k.unloadGuard = true;
  window.addEventListener("beforeunload", (event) => {
    if (window.__kinegami.unsaved) {
      event.preventDefault();
      event.returnValue = "";
      return "";
    }
  });
}
"""


def run_javascript(target: Any, source: str) -> bool:
    """Run ``source`` in the tab of ``target`` (a viser ClientHandle; a ViserServer: every
    tab). Returns False when ``target`` cannot run scripts (then nothing is sent)."""
    try:
        from viser import _messages
    except ImportError:  # pragma: no cover - viser is what the view runs on
        return False
    gui = getattr(target, "gui", None)
    interface = getattr(gui, "_websock_interface", None)
    message = getattr(_messages, "RunJavascriptMessage", None)
    if interface is None or message is None:
        return False
    interface.queue_message(message(source=source))
    return True


def unsaved_changes_script(unsaved: bool) -> str:
    """The script that tells the page whether closing it would lose unsaved changes (and
    installs the warning the first time)."""
    return _GUARD + f"window.__kinegami.unsaved = {json.dumps(bool(unsaved))};\n"
