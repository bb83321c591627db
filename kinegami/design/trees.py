"""Trees in design files (version 2): parents, the structure, and joint specifications.

Version 2 of the format adds three things to version 1, which loads unchanged:

* a joint may name its ``parent``: the index of an earlier entry of ``joints`` or its name
  (default: the previous entry, so a list without parents is the chain it always was);
* ``"structure"``: ``"chain"`` or ``"tree"``, what the loader returns (default: a
  :class:`~kinegami.tree.KinematicTree` when some parent is not the previous entry or the
  design is a joint specification, a :class:`~kinegami.chain.KinematicChain` otherwise);
* ``"placement": {"method": "wafr2024", "growthDirection": [x, y, z]}``: the joints are a *joint
  specification* (type, parameters, axis line, parent) that the tree construction places
  (:func:`kinegami.tree.from_specification`, reached only through :func:`construct_tree`,
  which imports it when such a design is loaded).

This module checks what the schema cannot say about them (:func:`check_tree_fields`) and turns a
specification into a plain description (:class:`TreeSpecification`); :func:`construct_tree` is
the one place that calls the construction.
"""

from __future__ import annotations

from dataclasses import dataclass

from kinegami.chain.joints import Joint
from kinegami.design.errors import DesignError, json_path
from kinegami.design.poses import rescaled_exactly
from kinegami.validation import shorten

__all__ = [
    "VERSION_2_FIELDS",
    "VERSION_3_FIELDS",
    "VERSION_4_FIELDS",
    "SPECIFICATION_METHODS",
    "TreeFields",
    "TreeSpecification",
    "check_version_features",
    "check_tree_fields",
    "structure_of",
    "construct_tree",
    "construction_available",
]

#: Top-level fields that need version 2.
VERSION_2_FIELDS = ("structure", "placement")
#: Top-level fields that need version 3 (which has every field of version 2).
VERSION_3_FIELDS = ("margin",)
#: Top-level fields that need version 4 (which has every field of version 3).
VERSION_4_FIELDS = ("material", "bed")
#: Methods of ``"placement"``: the tree constructions a joint specification can ask for.
SPECIFICATION_METHODS = ("wafr2024",)
#: Joint keys that a joint specification does not have (the construction places the joints).
_PLACED_BY_CONSTRUCTION = ("safe", "fixedPosition", "fixedOrientation")


def check_version_features(document: dict, file=None) -> None:
    """A DesignError for the first version-2 field of a design that says ``"version": 1``.

    Also the first version-3 field (``"margin"``) of a design that says 1 or 2, and the first
    version-4 field (``"material"``, ``"bed"``) of one that says 1, 2 or 3. Runs on the
    top-level shape only (``joints`` a list); cheap. The JSON Schema says the same for other
    validators.
    """
    version = document.get("version")
    for key in VERSION_4_FIELDS:
        if key in document and version in (1, 2, 3):
            raise DesignError(
                f"'{key}' is a field of version 4 of the format: write \"version\": 4 "
                f"(version {version} has no {key})",
                field=key,
                file=file,
            )
    for key in VERSION_3_FIELDS:
        if key in document and version in (1, 2):
            raise DesignError(
                f"'{key}' is a field of version 3 of the format: write \"version\": 3 "
                f"(version {version} has no {key})",
                field=key,
                file=file,
            )
    if version != 1:
        return
    for key in VERSION_2_FIELDS:
        if key in document:
            raise DesignError(
                f"'{key}' is a field of version 2 of the format: write \"version\": 2 "
                "(version 1 knows chains only)",
                field=key,
                file=file,
            )
    joints = document.get("joints")
    for i, spec in enumerate(joints if isinstance(joints, list) else ()):
        if isinstance(spec, dict) and "parent" in spec:
            raise DesignError(
                "a joint's 'parent' is a field of version 2 of the format: write "
                '"version": 2 (in version 1 every joint follows the previous one)',
                field=json_path(["joints", i, "parent"]),
                value=spec["parent"],
                file=file,
            )


@dataclass(frozen=True)
class TreeFields:
    """What the version-2 fields of a checked design say.

    Attributes
    ----------
    tree : build a KinematicTree (True) or a KinematicChain (False).
    parents : per entry of ``joints``, the entry it is added to (-1 for the root); empty for
        a DH design.
    specification : whether the joints are a joint specification (``"placement"``).
    """

    tree: bool
    parents: tuple
    specification: bool


def _what(specs, k: int) -> str:
    """``joints[k]`` with its type and name, for messages."""
    spec = specs[k]
    name = spec.get("name")
    label = f" '{shorten(name)}'" if name is not None else ""
    return f"joints[{k}] ({spec['type']}{label})"


def _parent_entry(ref, i: int, specs, names: dict, file) -> int:
    """The entry index the ``parent`` of ``joints[i]`` refers to (an earlier entry)."""
    where = json_path(["joints", i, "parent"])
    if isinstance(ref, str):
        if ref not in names:
            known = [n for n in names if n is not None]
            listed = ", ".join(f"'{shorten(n)}'" for n in known[:10])
            if len(known) > 10:
                listed += f", ... ({len(known)} names)"
            which = f"the joint names are {listed}" if known else "no entry of 'joints' has a name"
            raise DesignError(
                f"no joint is named '{shorten(ref)}' ({which}); a parent is the name or the "
                f"index of an earlier entry of 'joints' (0 to {i - 1})",
                field=where, value=ref, file=file,
            )  # fmt: skip
        k = names[ref]
        if k == i:
            raise DesignError(
                "a joint cannot be its own parent: the parent is an earlier entry of 'joints' "
                f"(0 to {i - 1}, by index or name)",
                field=where, value=ref, file=file,
            )  # fmt: skip
        if k > i:
            raise DesignError(
                f"the parent must come before the joint: '{shorten(ref)}' is {_what(specs, k)}, "
                f"after joints[{i}]; list every joint after its parent (which also makes "
                "cycles impossible)",
                field=where, value=ref, file=file,
            )  # fmt: skip
        return k
    k = int(ref)  # the schema allows integers >= 0 only
    if k >= i:
        own = "a joint cannot be its own parent; " if k == i else ""
        raise DesignError(
            f"{own}the parent must be an earlier entry of 'joints': joints[{i}] may name "
            f"joints[0] to joints[{i - 1}] (by index or name); list every joint after its "
            "parent (which also makes cycles impossible)",
            field=where, value=ref, file=file,
        )  # fmt: skip
    return k


def check_tree_fields(document: dict, file=None) -> TreeFields:
    """The parents and the structure of a schema-valid ``document`` (DesignError if wrong).

    Checks: parents name earlier entries (by index or an existing name); nothing is added to
    an EndTip; ``"structure": "chain"`` has no branches; a DH table is a chain; a joint
    specification has no ``safe``, ``fixedPosition`` or ``fixedOrientation``. The messages
    for a chain without parents are those of version 1.
    """
    structure = document.get("structure")
    specification = "placement" in document
    if "dh" in document:
        if structure == "tree":
            raise DesignError(
                'a DH table gives a chain: "structure" must be "chain" or absent '
                "(a tree is given by 'joints' with parents)",
                field="structure", value=structure, file=file,
            )  # fmt: skip
        return TreeFields(tree=False, parents=(), specification=False)
    if specification and structure == "chain":
        raise DesignError(
            'a joint specification ("placement") is placed by the tree construction, which '
            'makes a tree: "structure" must be "tree" or absent',
            field="structure", value=structure, file=file,
        )  # fmt: skip
    specs = document["joints"]
    names = {}
    for k, spec in enumerate(specs):
        if spec.get("name") is not None:
            names.setdefault(spec["name"], k)  # duplicates are reported by the name check
    parents = [-1]
    for i, spec in enumerate(specs[1:], start=1):
        if "parent" in spec:
            parents.append(_parent_entry(spec["parent"], i, specs, names, file))
        else:
            parents.append(i - 1)
    tree = structure == "tree" or specification or any(
        p != i - 1 for i, p in enumerate(parents)
    )
    if structure == "chain":
        for i, p in enumerate(parents[1:], start=1):
            if p != i - 1:
                raise DesignError(
                    f'a chain ("structure": "chain") has no branches: the parent of joints[{i}] '
                    f'must be the previous entry, joints[{i - 1}]; write "structure": "tree" '
                    "for a tree",
                    field=json_path(["joints", i, "parent"]), value=specs[i].get("parent"),
                    file=file,
                )  # fmt: skip
    if tree:
        _check_tree_order(specs, parents, file)
    if specification:
        _check_growth_direction(document["placement"], file)
        if "maxAnglePerElbow" in document:
            raise DesignError(
                "a joint specification (\"placement\") has no maxAnglePerElbow: the tree "
                "construction makes its elbows at most pi/10 (18 degrees); leave it out",
                field="maxAnglePerElbow", value=document["maxAnglePerElbow"], file=file,
            )  # fmt: skip
        for i, spec in enumerate(specs[1:], start=1):
            for key in _PLACED_BY_CONSTRUCTION:
                if key in spec:
                    raise DesignError(
                        f"a joint specification (\"placement\") has no '{key}': the "
                        "construction places every joint on the axis line of its pose "
                        "('relative' says whether the pose is relative to the parent's)",
                        field=json_path(["joints", i, key]), value=spec[key], file=file,
                    )  # fmt: skip
    return TreeFields(tree=tree, parents=tuple(parents), specification=specification)


def structure_of(document: dict) -> str:
    """``"tree"`` or ``"chain"``: what a checked design document loads as."""
    if "structure" in document:
        return document["structure"]
    if "placement" in document:
        return "tree"
    specs = document.get("joints", ())
    names = {spec.get("name"): k for k, spec in enumerate(specs)}  # unique when checked
    for i, spec in enumerate(specs[1:], start=1):
        ref = spec.get("parent", i - 1)
        if (names.get(ref) if isinstance(ref, str) else ref) != i - 1:
            return "tree"
    return "chain"


def _check_tree_order(specs, parents, file) -> None:
    """StartTip only as the root; nothing added to an EndTip (a tree's leaves)."""
    for i, spec in enumerate(specs):
        kind = spec["type"]
        if kind == "StartTip" and i > 0:
            raise DesignError(
                "a StartTip can only be the root (joints[0])",
                field=json_path(["joints", i, "type"]), value=kind, file=file,
            )  # fmt: skip
        if kind == "EndTip" and i == 0:
            raise DesignError(
                "the root (joints[0]) cannot be an EndTip: nothing may follow an EndTip",
                field=json_path(["joints", 0, "type"]), value=kind, file=file,
            )  # fmt: skip
    for i, p in enumerate(parents):
        if p < 0 or specs[p]["type"] != "EndTip":
            continue
        if "parent" in specs[i]:
            raise DesignError(
                f"an EndTip cannot be a parent: {_what(specs, p)} is an EndTip, and nothing "
                "may follow an EndTip (an EndTip is a leaf of the tree)",
                field=json_path(["joints", i, "parent"]), value=specs[i]["parent"], file=file,
            )  # fmt: skip
        raise DesignError(
            f"this joint has no 'parent', so it follows the previous entry, {_what(specs, p)}, "
            "an EndTip: nothing may follow an EndTip; give it a \"parent\"",
            field=json_path(["joints", i]), file=file,
        )  # fmt: skip


def _check_growth_direction(placement: dict, file) -> None:
    if "growthDirection" in placement and rescaled_exactly(placement["growthDirection"]) is None:
        raise DesignError(
            "the growth direction must be a non-zero vector",
            field="placement.growthDirection", value=placement["growthDirection"], file=file,
        )  # fmt: skip


# --- joint specifications --------------------------------------------------------------------
@dataclass(frozen=True)
class TreeSpecification:
    """A joint specification read from a design: the input of the tree construction.

    Attributes
    ----------
    method : the construction (``"wafr2024"``).
    joints : the specified joints in file order, their poses global (a ``relative`` pose
        already composed with the parent's specified pose); only type, parameters and the
        axis line (the pose's origin and z axis) bind the construction.
    parents : per joint, the index of its parent in ``joints`` (-1 for the root).
    names : per joint, its ``name`` in the file, or None.
    growth_direction : the direction the tree grows along as written (non-zero; the
        construction normalises it), or None (the construction chooses).
    extra_roll : the published extra roll after each placement (None: the construction's
        default, without).
    sibling_azimuth : the azimuth step in radians between the routes of later siblings (None:
        the construction's default; 0 gives the published construction).
    """

    method: str
    joints: tuple
    parents: tuple
    names: tuple
    growth_direction: tuple | None = None
    extra_roll: bool | None = None
    sibling_azimuth: float | None = None

    @classmethod
    def of(
        cls, document: dict, joints: list, parents, relative: list, names, to_radians
    ) -> TreeSpecification:
        """The specification of a checked design: ``joints`` as constructed from the
        entries (poses as written), ``relative`` per entry, ``to_radians`` the file's angle
        unit conversion."""
        placed: list[Joint] = []
        for i, joint in enumerate(joints):
            p = parents[i]
            if p >= 0 and relative[i]:
                joint = joint.with_pose(placed[p].pose_matrix @ joint.pose_matrix)
            placed.append(joint)
        placement = document["placement"]
        direction = None
        if "growthDirection" in placement:  # as written: the construction normalises it
            direction = tuple(float(c) for c in placement["growthDirection"])
        azimuth = placement.get("siblingAzimuth")
        return cls(
            method=placement["method"],
            joints=tuple(placed),
            parents=tuple(parents),
            names=tuple(names),
            growth_direction=direction,
            extra_roll=placement.get("extraRoll"),
            sibling_azimuth=None if azimuth is None else to_radians(azimuth),
        )


def construction_available() -> bool:
    """Whether the tree construction (kinegami.tree.construction) can be imported."""
    try:
        from kinegami.tree import construction  # noqa: F401
    except ImportError:
        return False
    return True


def construct_tree(spec: TreeSpecification, file=None):
    """Build the tree of a joint specification with :func:`kinegami.tree.from_specification`.

    Returns ``(tree, sources)``: the KinematicTree and, per joint of the tree, the index of the
    specified joint it places (None for the waypoints the construction adds). Imports the
    construction on first use; a DesignError at ``placement`` when it is not available. The
    construction's own errors (a KinegamiError) are the caller's to report.
    """
    try:
        from kinegami.tree import construction
    except ImportError as error:
        raise DesignError(
            "joint specifications cannot be built: the tree construction "
            f"(kinegami.tree.construction) is not available ({error})",
            field="placement", file=file,
        ) from None  # fmt: skip
    taken = {name for name in spec.names if name is not None}

    def name_of(i: int) -> str | None:  # the construction's messages name the joints
        if spec.names[i] is not None:
            return spec.names[i]
        label = f"joints[{i}]"
        return None if label in taken else label

    specification = construction.JointSpecificationTree(spec.joints[0], name_of(0) or "root")
    for i in range(1, len(spec.joints)):
        specification.addJoint(spec.parents[i], spec.joints[i], relative=False, name=name_of(i))
    options = {}
    if spec.growth_direction is not None:
        options["growth_direction"] = spec.growth_direction
    if spec.extra_roll is not None:
        options["extra_roll"] = spec.extra_roll
    if spec.sibling_azimuth is not None:
        options["sibling_azimuth"] = spec.sibling_azimuth
    tree = construction.from_specification(specification, **options)
    sources: list = [None] * len(tree.Joints)
    for k, node in enumerate(tree.construction.node_of):
        sources[node] = k
    return tree, sources
