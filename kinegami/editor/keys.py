"""The editor's keyboard shortcuts (docs/editor.md, Keyboard shortcuts).

viser has no keyboard events. The editor puts a small script in the tab (through
:func:`kinegami.editor.page_script.run_javascript`) that listens for the shortcut keys and
clicks the panel button that does the same thing, found by the button's element id (viser
gives each button the id of its GUI element). So a key does exactly what its button does,
through viser's own messages, and the server needs no second way in. Keys are ignored while
the focus is in a text or number field (Escape there only leaves the field), and the keys the
editor uses do not reach viser's own camera keys (Ctrl+S is not the S of WASD).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Any

from kinegami.errors import InvalidParameterError

__all__ = ["SHORTCUTS", "shortcuts_markdown", "keys_script", "element_id"]

#: (keys, action, what it does): the help panel's table, in order. ``action`` is what the
#: script asks the view for (see :func:`keys_script`).
SHORTCUTS: tuple[tuple[str, str, str], ...] = (
    ("Ctrl+Z", "undo", "undo the last command"),
    ("Ctrl+Shift+Z, Ctrl+Y", "redo", "redo what was undone"),
    ("Delete", "delete", "delete the selected joint"),
    ("F", "frame", "frame all: the whole design in view"),
    ("Ctrl+S", "save", "save the design file (a design with no file on the server: download "
                       "it)"),  # fmt: skip
    ("Escape", "escape", "close a dialog, else cancel a handle drag, else deselect"),
)
#: The actions, in order.
ACTIONS = tuple(action for _, action, _ in SHORTCUTS)

_SCRIPT = """
const k = (window.__kinegami = window.__kinegami || {});
k.keyTargets = %(targets)s;
k.keyPresses = k.keyPresses || [];
if (!k.keysInstalled) {
  k.keysInstalled = true;
  const typing = (el) => !!el && (el.tagName === "INPUT" || el.tagName === "TEXTAREA" ||
                                  el.tagName === "SELECT" || el.isContentEditable);
  const actionOf = (e) => {
    const key = (e.key || "").toLowerCase();
    const ctrl = e.ctrlKey || e.metaKey;
    if (ctrl && !e.altKey) {
      if (key === "z") return e.shiftKey ? "redo" : "undo";
      if (key === "y" && !e.shiftKey) return "redo";
      if (key === "s" && !e.shiftKey) return "save";
      return null;
    }
    if (ctrl || e.altKey || e.shiftKey) return null;
    if (key === "delete") return "delete";
    if (key === "f") return "frame";
    if (key === "escape") return "escape";
    return null;
  };
  window.addEventListener("keydown", (e) => {
    const action = actionOf(e);
    if (action === null) return;
    const focus = document.activeElement;
    if (typing(e.target) || typing(focus)) {
      if (action === "escape" && focus && focus.blur) focus.blur();
      return;
    }
    const ids = (window.__kinegami.keyTargets || {})[action] || [];
    for (const id of ids) {
      const button = document.getElementById(id);
      if (button && !button.disabled) {
        e.preventDefault();
        e.stopImmediatePropagation();
        if (!e.repeat) {
          window.__kinegami.keyPresses.push(action);
          button.click();
        }
        return;
      }
    }
  }, true);
}
"""


def element_id(handle: Any) -> str | None:
    """The page element id viser gives a GUI element (its uuid), or None when the handle
    has none (a viser without it: the shortcuts then do nothing)."""
    impl = getattr(handle, "_impl", None)
    uuid = getattr(impl, "uuid", None)
    return uuid if isinstance(uuid, str) else None


def keys_script(targets: Mapping[str, Sequence[Any]]) -> str:
    """The script that installs the shortcuts in a tab (once) and points each action at its
    buttons: ``targets`` maps an action of :data:`SHORTCUTS` to the button handles that do
    it, tried in order (the first one on the page and enabled is clicked: a hidden button is
    not on the page). Running it again only updates the buttons."""
    unknown = sorted(set(targets) - set(ACTIONS))
    if unknown:
        raise InvalidParameterError(f"unknown shortcut action {unknown[0]!r}; the actions are "
                         f"{', '.join(ACTIONS)}")  # fmt: skip
    ids = {action: [i for i in map(element_id, targets.get(action, ())) if i]
           for action in ACTIONS}  # fmt: skip
    return _SCRIPT % {"targets": json.dumps(ids, sort_keys=True)}


def shortcuts_markdown() -> str:
    """The help panel: a table of the shortcuts."""
    rows = [f"| {keys} | {what} |" for keys, _, what in SHORTCUTS]
    return "\n".join(["| key | does |", "|---|---|", *rows,
                      "", "Keys do nothing while you type in a field."])  # fmt: skip
