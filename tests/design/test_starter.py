"""The starter design of ``kinegami new`` (kinegami.design.starter): valid, buildable, written
whole or not at all, never over an existing file unless asked."""

from __future__ import annotations

import errno
import json
import os

import pytest

from kinegami.chain.joints import EndTip, PrismaticJoint, RevoluteJoint, StartTip
from kinegami.design import check_pattern, load_design_with_info, validate_design
from kinegami.design.starter import (
    DesignFileExistsError,
    starter_document,
    starter_text,
    write_starter_design,
)
from kinegami.errors import InvalidParameterError, KinegamiError


def test_written_file_validates_builds_and_is_named_after_the_file(tmp_path):
    path = write_starter_design(tmp_path / "my_robot.json")
    assert path == tmp_path / "my_robot.json"
    validate_design(path)
    chain, info = load_design_with_info(path)
    assert info.name == "my_robot" and info.units == "mm"
    structural = [type(j) for j in chain.Joints if type(j).__name__ != "Waypoint"]
    assert structural == [StartTip, RevoluteJoint, PrismaticJoint, EndTip]
    pattern = check_pattern(chain, info)
    assert pattern.width > 0 and pattern.height > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["my_robot.json"]  # no temporary left


def test_text_is_the_document(tmp_path):
    assert json.loads(starter_text("x")) == starter_document("x")
    assert starter_document()["name"] == "my robot"
    doc = starter_document()
    doc["joints"].clear()  # a new document every call
    assert len(starter_document()["joints"]) == 4


def test_an_existing_file_is_kept(tmp_path):
    path = tmp_path / "arm.json"
    path.write_text("my own design")
    with pytest.raises(DesignFileExistsError, match="arm.json") as info:
        write_starter_design(path)
    assert isinstance(info.value, KinegamiError) and isinstance(info.value, FileExistsError)
    assert path.read_text() == "my own design"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.json"]


def test_a_dangling_symlink_is_not_followed(tmp_path):
    link = tmp_path / "arm.json"
    link.symlink_to(tmp_path / "elsewhere.json")
    with pytest.raises(DesignFileExistsError):
        write_starter_design(link)
    assert not (tmp_path / "elsewhere.json").exists()


def test_overwrite_replaces(tmp_path):
    path = tmp_path / "arm.json"
    path.write_text("old")
    write_starter_design(path, overwrite=True)
    assert json.loads(path.read_text())["name"] == "arm"


def test_a_file_that_appears_while_writing_is_kept(tmp_path, monkeypatch):
    """Another program creates the file between the check and the publication."""
    from kinegami.design import starter

    path = tmp_path / "arm.json"
    real = starter.write_atomic

    def racing(target, text):
        real(target, text)
        path.write_text("theirs")

    monkeypatch.setattr(starter, "write_atomic", racing)
    with pytest.raises(DesignFileExistsError):
        write_starter_design(path)
    assert path.read_text() == "theirs"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.json"]


def test_without_hard_links_the_file_is_renamed_into_place(tmp_path, monkeypatch):
    def no_links(src, dst):
        raise OSError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(os, "link", no_links)
    path = write_starter_design(tmp_path / "sub" / "arm.json")  # missing folders are made
    validate_design(path)
    assert sorted(p.name for p in path.parent.iterdir()) == ["arm.json"]


@pytest.mark.parametrize("name", ["arm.txt", "arm", ".json"])
def test_the_name_must_end_in_json(tmp_path, name):
    with pytest.raises(InvalidParameterError, match=r"\.json"):
        write_starter_design(tmp_path / name)
    assert list(tmp_path.iterdir()) == []
