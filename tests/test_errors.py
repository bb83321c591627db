"""Bad input: every check raises a KinegamiError subclass that is also the matching builtin,
with a message naming the parameter and the value, and leaves the chain bit-identical."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest
from spatialmath import SE3

from kinegami import (
    EndTip,
    IncompatibleJointError,
    InvalidParameterError,
    InvalidTypeError,
    JointIndexError,
    KinegamiError,
    KinematicChain,
    LinkCSC,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)

NAN, INF = math.nan, math.inf


def check_error(excinfo, builtin, name, value=None):
    """The error is a KinegamiError and ``builtin``; its message names ``name`` and ``value``."""
    error = excinfo.value
    assert isinstance(error, KinegamiError)
    assert isinstance(error, builtin)
    message = str(error)
    assert re.search(rf"(?<![A-Za-z_]){re.escape(name)}(?![A-Za-z_])", message), message
    if value is not None:
        assert str(value) in message, message


def test_hierarchy():
    assert issubclass(InvalidParameterError, ValueError)
    assert issubclass(InvalidTypeError, TypeError)
    assert issubclass(JointIndexError, IndexError)
    assert issubclass(IncompatibleJointError, ValueError)
    for cls in (InvalidParameterError, InvalidTypeError, JointIndexError, IncompatibleJointError):
        assert issubclass(cls, KinegamiError)


# --- one hierarchy, in kinegami.errors (docs/errors.md) ----------------------------------------

#: Every class of kinegami.errors and the builtins it must also be.
HIERARCHY = {
    "KinegamiError": (Exception,),
    "InvalidParameterError": (ValueError,),
    "InvalidTypeError": (TypeError,),
    "ReadOnlyError": (AttributeError,),
    "JointIndexError": (IndexError,),
    "NoPathError": (ValueError,),
    "IncompatibleJointError": (ValueError,),
    "CompactionError": (ValueError,),
    "InfeasibleTaskError": (ValueError,),
    "SplitError": (ValueError,),
    "BedTooSmallError": (ValueError,),
    "EditorCommandError": (ValueError,),
    "FoldedFormError": (ValueError,),
    "UnknownModuleKindError": (ValueError, KeyError),
    "DesignError": (ValueError,),
    "DesignFileExistsError": (FileExistsError,),
    "ExportError": (OSError,),
    "PublishError": (OSError,),
    "ExporterUnavailableError": (ImportError,),
    "FoldExportError": (ValueError,),
    "Cancelled": (Exception,),
    "GuardError": (RuntimeError,),
    "PlacementWarning": (UserWarning,),
    "ClearanceWarning": (UserWarning,),
}

#: Old import locations (module, name) that must give the class of kinegami.errors.
OLD_LOCATIONS = [
    ("kinegami", "KinegamiError"),
    ("kinegami", "InvalidParameterError"),
    ("kinegami.chain", "PlacementWarning"),
    ("kinegami.chain", "ClearanceWarning"),
    ("kinegami.design", "DesignError"),
    ("kinegami.design.errors", "DesignError"),
    ("kinegami.design.starter", "DesignFileExistsError"),
    ("kinegami.pattern.folded", "FoldedFormError"),
    ("kinegami.optimize", "CompactionError"),
    ("kinegami.pattern.catalog", "UnknownModuleKindError"),
    ("kinegami.export", "ExportError"),
    ("kinegami.export.publish", "PublishError"),
    ("kinegami.export.registry", "ExporterUnavailableError"),
    ("kinegami.export.fold", "FoldExportError"),
]

#: Old locations whose module still defines its own class (owned by other modules' authors;
#: each should become ``from kinegami.errors import <name>``). xfail until then, not strict.
PENDING_LOCATIONS: list = []


def test_errors_module_lists_the_whole_hierarchy():
    import kinegami.errors as errors

    assert sorted(errors.__all__) == sorted(HIERARCHY)
    for name in HIERARCHY:
        assert name in errors.__doc__, name


@pytest.mark.parametrize("name", sorted(HIERARCHY))
def test_every_error_is_a_kinegami_error_and_its_builtin(name):
    import kinegami.errors as errors

    cls = getattr(errors, name)
    assert cls.__module__ == "kinegami.errors"
    for builtin in HIERARCHY[name]:
        assert issubclass(cls, builtin)
    assert issubclass(cls, Warning) or issubclass(cls, KinegamiError)


@pytest.mark.parametrize(("module", "name"), OLD_LOCATIONS)
def test_old_import_locations_give_the_same_class(module, name):
    import importlib

    import kinegami.errors as errors

    assert getattr(importlib.import_module(module), name) is getattr(errors, name)


@pytest.mark.parametrize(
    ("module", "name"),
    [pytest.param(*where, marks=pytest.mark.xfail(reason="defined in a module of another "
                                                   "author; to import from kinegami.errors"))
     for where in PENDING_LOCATIONS],
)  # fmt: skip
def test_pending_import_locations_give_the_same_class(module, name):
    import importlib

    import kinegami.errors as errors

    assert getattr(importlib.import_module(module), name) is getattr(errors, name)


def _package_classes():
    """(module, class) of every public exception or warning class defined in the package,
    except front ends (the CLI's CommandError is how it leaves a command, never raised to a
    user of the library)."""
    import importlib
    import inspect
    import pkgutil

    import kinegami

    found = []
    for info in pkgutil.walk_packages(kinegami.__path__, "kinegami."):
        if info.name in ("kinegami.cli", "kinegami.__main__") or "._" in info.name:
            continue
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if (
                inspect.isclass(obj)
                and issubclass(obj, BaseException)
                and not name.startswith("_")
                and obj.__module__ == info.name
            ):
                found.append((info.name, name))
    return found


def test_no_module_but_errors_defines_a_public_error_class():
    pending = {name for _, name in PENDING_LOCATIONS}
    stray = [
        f"{module}.{name}"
        for module, name in _package_classes()
        if module != "kinegami.errors" and name not in pending
    ]
    assert stray == []


def test_the_version_is_the_one_of_pyproject():
    import pathlib
    import tomllib

    import kinegami
    from kinegami._version import __version__

    root = pathlib.Path(__file__).resolve().parent.parent
    project = tomllib.loads((root / "pyproject.toml").read_text("utf-8"))["project"]
    assert __version__ == project["version"] == kinegami.__version__


# --- shared parameter checks (kinegami.validation) ---------------------------------------------


@pytest.mark.parametrize("value", [True, False, np.True_, np.False_])
def test_check_bool_accepts_python_and_numpy_booleans(value):
    from kinegami.validation import check_bool

    result = check_bool("flag", value)
    assert type(result) is bool and result == bool(value)


@pytest.mark.parametrize("value", [0, 1, 1.0, "yes", None, [True], np.array([True, False])])
def test_check_bool_refuses_everything_else(value):
    from kinegami.validation import check_bool

    with pytest.raises(InvalidTypeError) as excinfo:
        check_bool("endTip", value)
    check_error(excinfo, TypeError, "endTip")
    assert str(excinfo.value).startswith("endTip must be True or False, got ")


def test_check_options_names_the_unknown_and_the_valid_options():
    from kinegami.validation import check_options

    check_options({"units": "mm"}, ("units", "scale"), "DXF export")
    with pytest.raises(InvalidTypeError) as excinfo:
        check_options({"unit": "mm"}, ("units", "scale"), "DXF export")
    assert str(excinfo.value) == (
        "DXF export got unknown option 'unit'; valid options are: units, scale"
    )
    with pytest.raises(InvalidTypeError) as excinfo:
        check_options({"b": 1, "a": 2, "units": 3}, ("units", "scale"), "show()")
    assert str(excinfo.value) == (
        "show() got unknown options 'a', 'b'; valid options are: units, scale"
    )


def test_resolve_options_fills_in_the_defaults():
    from kinegami.validation import resolve_options

    defaults = {"units": "mm", "scale": 1.0}
    assert resolve_options({"scale": 2.0}, defaults, "SVG export") == {"units": "mm", "scale": 2.0}
    assert defaults == {"units": "mm", "scale": 1.0}
    with pytest.raises(InvalidTypeError, match="SVG export got unknown option 'colour'"):
        resolve_options({"colour": "red"}, defaults, "SVG export")


def test_dh_end_tip_uses_the_shared_bool_check():
    with pytest.raises(InvalidTypeError, match=r"^endTip must be True or False, got 1$"):
        KinematicChain.from_dh([[0.0, 0.0, 0.0, 0.0]], 4, 1.0, endTip=1)


def test_starter_design_overwrite_must_be_a_bool(tmp_path):
    from kinegami.design.starter import write_starter_design

    with pytest.raises(InvalidTypeError, match=r"^overwrite must be True or False, got 'no'$"):
        write_starter_design(tmp_path / "robot.json", overwrite="no")
    assert not (tmp_path / "robot.json").exists()


# --- joint constructors ----------------------------------------------------------------------

CONSTRUCTORS = {
    "RevoluteJoint": lambda n=4, r=1.0, **kw: RevoluteJoint(
        n, r, kw.get("bend", math.pi), kw.get("pose", SE3())
    ),
    "PrismaticJoint": lambda n=4, r=1.0, **kw: PrismaticJoint(
        n, r, 3.0, 3, kw.get("cone", math.pi / 4), kw.get("pose", SE3())
    ),
    "Waypoint": lambda n=4, r=1.0, **kw: Waypoint(n, r, kw.get("pose", SE3())),
    "StartTip": lambda n=4, r=1.0, **kw: StartTip(n, r, kw.get("pose", SE3()), 1.5),
    "EndTip": lambda n=4, r=1.0, **kw: EndTip(n, r, kw.get("pose", SE3()), 1.5),
}


@pytest.mark.parametrize("kind", CONSTRUCTORS)
@pytest.mark.parametrize("n", [5, 7, 3, 2, 0, -4])
def test_num_sides_odd_or_too_small(kind, n):
    with pytest.raises(InvalidParameterError) as excinfo:
        CONSTRUCTORS[kind](n=n)
    check_error(excinfo, ValueError, "numSides", n)


@pytest.mark.parametrize("kind", CONSTRUCTORS)
@pytest.mark.parametrize("n", [1026, 10**30])
def test_num_sides_too_many(kind, n):
    """10**30 sides were accepted; the first pattern then failed deep in numpy."""
    with pytest.raises(InvalidParameterError) as excinfo:
        CONSTRUCTORS[kind](n=n)
    check_error(excinfo, ValueError, "numSides", n)
    assert "[4, 1024]" in str(excinfo.value)


def test_num_sides_at_the_cap_build():
    assert RevoluteJoint(1024, 1.0, math.pi, SE3()).numSides == 1024


@pytest.mark.parametrize("kind", CONSTRUCTORS)
@pytest.mark.parametrize("n", [4.5, "4", None, True])
def test_num_sides_not_an_integer(kind, n):
    with pytest.raises(InvalidTypeError) as excinfo:
        CONSTRUCTORS[kind](n=n)
    check_error(excinfo, TypeError, "numSides", n)


@pytest.mark.parametrize("kind", CONSTRUCTORS)
@pytest.mark.parametrize("r", [0, -1, -1e-300, NAN, INF, -INF])
def test_radius_not_positive_and_finite(kind, r):
    with pytest.raises(InvalidParameterError) as excinfo:
        CONSTRUCTORS[kind](r=r)
    check_error(excinfo, ValueError, "r", r)


@pytest.mark.parametrize("kind", CONSTRUCTORS)
def test_radius_not_a_number(kind):
    with pytest.raises(InvalidTypeError) as excinfo:
        CONSTRUCTORS[kind](r="1")
    check_error(excinfo, TypeError, "r", "1")


@pytest.mark.parametrize("cone", [math.pi / 6 - 1e-6, 0.0, -0.5, math.pi / 2, 2.0, NAN, INF])
def test_cone_angle_outside_range(cone):
    with pytest.raises(InvalidParameterError) as excinfo:
        CONSTRUCTORS["PrismaticJoint"](cone=cone)
    check_error(excinfo, ValueError, "coneAngle", cone)


@pytest.mark.parametrize("bend", [0.0, -1.0, 2 * math.pi, 7.0, NAN, INF])
def test_total_bending_angle_outside_range(bend):
    with pytest.raises(InvalidParameterError) as excinfo:
        CONSTRUCTORS["RevoluteJoint"](bend=bend)
    check_error(excinfo, ValueError, "totalBendingAngle", bend)


def reflected():
    return np.diag([1.0, 1.0, -1.0, 1.0])


def scaled():
    T = 2 * np.eye(4)
    T[3, 3] = 1
    return T


def slightly_scaled():
    T = np.eye(4)
    T[:3, :3] *= 1.0001
    return T


def sheared():
    T = np.eye(4)
    T[0, 1] = 0.3
    return T


def with_nan():
    T = np.eye(4)
    T[1, 3] = NAN
    return T


def with_inf():
    T = np.eye(4)
    T[0, 0] = INF
    return T


def bad_last_row():
    T = np.eye(4)
    T[3, 0] = 1.0
    return T


#: name -> (bad pose, expected error, a fragment of the message showing the value)
BAD_POSES = {
    "reflection": (reflected, InvalidParameterError, "-1."),
    "scaled": (scaled, InvalidParameterError, "2."),
    "slightly scaled": (slightly_scaled, InvalidParameterError, "1.0001"),
    "sheared": (sheared, InvalidParameterError, "0.3"),
    "contains NaN": (with_nan, InvalidParameterError, "NaN"),
    "contains inf": (with_inf, InvalidParameterError, "inf"),
    "last row": (bad_last_row, InvalidParameterError, None),
    "3x3": (lambda: np.eye(3), InvalidParameterError, "(3, 3)"),
    "4x3": (lambda: np.eye(4)[:, :3], InvalidParameterError, "(4, 3)"),
    "vector": (lambda: np.zeros(16), InvalidParameterError, "(16,)"),
    "text": (lambda: "identity", InvalidTypeError, "str"),
    # not real numbers (np.array(..., dtype=float) read them as numbers, bools as 0 and 1)
    "None": (lambda: None, InvalidTypeError, "got None"),
    "strings": (lambda: string_rows(), InvalidTypeError, "str '1'"),
    "string array": (lambda: np.array(string_rows()), InvalidTypeError, "<U1"),
    "bool array": (lambda: np.eye(4, dtype=bool), InvalidTypeError, "dtype bool"),
    "bools in a list": (lambda: with_entry(True), InvalidTypeError, "[3][3] is bool True"),
    "numpy bool in a list": (lambda: with_entry(np.bool_(True)), InvalidTypeError, "[3][3]"),
    "complex array": (lambda: np.eye(4) + 0j, InvalidTypeError, "complex128"),
    "complex in a list": (lambda: with_entry(1 + 0j), InvalidTypeError, "(1+0j)"),
    "None in an object array": (
        lambda: np.array(with_entry(None), dtype=object),
        InvalidTypeError,
        "[3][3] is None",
    ),
    "ragged rows": (lambda: np.eye(4).tolist()[:3] + [[0, 0, 1]], InvalidTypeError, "length"),
}


def string_rows():
    """The identity moved to x = 5, in strings (was a valid pose)."""
    return [["1", "0", "0", "5"], ["0", "1", "0", "0"], ["0", "0", "1", "0"], ["0", "0", "0", "1"]]


def with_entry(value):
    """The identity as nested lists with ``value`` as its last entry."""
    rows = np.eye(4).tolist()
    rows[3][3] = value
    return rows


@pytest.mark.parametrize(
    "case", [case for case, (_, error, _) in BAD_POSES.items() if error is InvalidTypeError]
)
def test_pose_of_the_wrong_type_warns_nothing(case):
    """No numpy warning (ComplexWarning) on the way to the InvalidTypeError."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InvalidTypeError):
            RevoluteJoint(4, 1, math.pi, BAD_POSES[case][0]())


def _valid_pose_forms():
    """(name, pose) of the forms a valid pose may take, all the same integer transform."""
    from fractions import Fraction

    T = np.array([[0, -1, 0, 5], [1, 0, 0, -2], [0, 0, 1, 3], [0, 0, 0, 1]])
    return [
        ("SE3", SE3(T.astype(float))),
        ("float array", T.astype(float)),
        ("int array", T),
        ("int8 array", T.astype(np.int8)),
        ("float32 array", T.astype(np.float32)),
        ("object array", np.array(T.tolist(), dtype=object)),
        ("list of lists", T.tolist()),
        ("tuple of tuples", tuple(map(tuple, T.tolist()))),
        ("list of arrays", list(T.astype(float))),
        ("numpy scalars", [[np.float64(v) for v in row] for row in T]),
        ("fractions", [[Fraction(int(v)) for v in row] for row in T]),
    ]


def test_valid_pose_forms_give_the_same_joint_and_edit(example_1a_factory, snapshot):
    forms = _valid_pose_forms()
    expected = np.array(forms[1][1], dtype=float)
    same = example_1a_factory()
    same_result = same.transformJoint(4, SE3(expected))
    for name, pose in forms:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            joint = RevoluteJoint(4, 1, math.pi, pose)
            chain = example_1a_factory()
            result = chain.transformJoint(4, pose)
        assert joint.pose_matrix.tobytes() == expected.tobytes(), name
        assert joint.pose_matrix.dtype == np.float64 and joint.pose_matrix.shape == (4, 4)
        assert result == same_result, name
        assert snapshot(chain) == snapshot(same), name


@pytest.mark.parametrize("kind", CONSTRUCTORS)
@pytest.mark.parametrize("case", BAD_POSES)
def test_joint_pose_not_a_rigid_transform(kind, case):
    make, error, fragment = BAD_POSES[case]
    with pytest.raises(error) as excinfo:
        CONSTRUCTORS[kind](pose=make())
    check_error(
        excinfo, ValueError if error is InvalidParameterError else TypeError, "Pose", fragment
    )


@pytest.mark.parametrize("kind", CONSTRUCTORS)
def test_valid_array_pose_is_accepted(kind):
    T = (SE3.Trans(1, 2, 3) * SE3.RPY(0.1, 0.2, 0.3)).A
    joint = CONSTRUCTORS[kind](pose=T)
    np.testing.assert_array_equal(joint.pose_matrix, T)


@pytest.mark.parametrize("k", [3, -1, 0.5])
def test_waypoint_path_index(k):
    with pytest.raises((InvalidParameterError, InvalidTypeError)) as excinfo:
        Waypoint(4, 1, SE3(), pathIndex=k)
    check_error(excinfo, (ValueError, TypeError), "pathIndex", k)


# --- LinkCSC ---------------------------------------------------------------------------------

BAD_MAX_ANGLES = [0.0, -0.1, math.pi + 1e-9, 4.0, NAN, INF]


@pytest.mark.parametrize("max_angle", BAD_MAX_ANGLES)
def test_link_max_angle_per_elbow(max_angle):
    with pytest.raises(InvalidParameterError) as excinfo:
        LinkCSC(1.0, SE3(), SE3.Trans(5, 0, 0), max_angle)
    check_error(excinfo, ValueError, "maxAnglePerElbow", max_angle)


def test_link_max_angle_pi_is_accepted():
    link = LinkCSC(1.0, SE3(), SE3.Trans(0, 10, 5) * SE3.Ry(-math.pi / 2), math.pi)
    assert link.elbows1.count == 1 and link.elbows2.count == 1


@pytest.mark.parametrize("r", [0, -2.0, NAN, INF])
def test_link_radius(r):
    with pytest.raises(InvalidParameterError) as excinfo:
        LinkCSC(r, SE3(), SE3.Trans(5, 0, 0))
    check_error(excinfo, ValueError, "r", r)


@pytest.mark.parametrize("which", ["StartDubinsPose", "EndDubinsPose"])
@pytest.mark.parametrize("case", BAD_POSES)
def test_link_frames(which, case):
    make, error, fragment = BAD_POSES[case]
    frames = {"StartDubinsPose": SE3(), "EndDubinsPose": SE3.Trans(5, 0, 0)}
    frames[which] = make()
    with pytest.raises(error) as excinfo:
        LinkCSC(1.0, frames["StartDubinsPose"], frames["EndDubinsPose"])
    check_error(
        excinfo, ValueError if error is InvalidParameterError else TypeError, which, fragment
    )


# --- chain construction ------------------------------------------------------------------------


@pytest.mark.parametrize("max_angle", BAD_MAX_ANGLES)
def test_chain_max_angle_per_elbow(max_angle):
    with pytest.raises(InvalidParameterError) as excinfo:
        KinematicChain(StartTip(4, 1, SE3(), 1.5), max_angle)
    check_error(excinfo, ValueError, "maxAnglePerElbow", max_angle)


def test_chain_root_must_be_a_joint():
    with pytest.raises(InvalidTypeError) as excinfo:
        KinematicChain(SE3())
    check_error(excinfo, TypeError, "startJoint", "SE3")


def test_chain_root_cannot_be_an_end_tip():
    with pytest.raises(InvalidParameterError) as excinfo:
        KinematicChain(EndTip(4, 1, SE3(), 1.5))
    check_error(excinfo, ValueError, "startJoint", "EndTip")


# --- chain methods: each error leaves the chain bit-identical --------------------------------


@pytest.fixture
def chain_and_snapshot(example_1a, snapshot):
    return example_1a, snapshot(example_1a), snapshot


def assert_unchanged(chain_and_snapshot):
    chain, before, snapshot = chain_and_snapshot
    assert snapshot(chain) == before


@pytest.mark.parametrize(
    "n, r, name, value", [(6, 1.0, "numSides", 6), (4, 1.5, "r", 1.5), (8, 2.0, "numSides", 8)]
)
@pytest.mark.parametrize("safe", [True, False])
def test_append_joint_with_another_tube(chain_and_snapshot, n, r, name, value, safe):
    chain = chain_and_snapshot[0]
    chain.delete(-1)  # drop the EndTip so appending is otherwise allowed
    chain_and_snapshot = (chain, chain_and_snapshot[2](chain), chain_and_snapshot[2])
    with pytest.raises(IncompatibleJointError) as excinfo:
        chain.append(RevoluteJoint(n, r, math.pi, SE3()), safe=safe)
    check_error(excinfo, ValueError, name, value)
    assert_unchanged(chain_and_snapshot)


@pytest.mark.parametrize("flag", ["fixedPosition", "fixedOrientation"])
def test_append_safe_with_fixed_pose(chain_and_snapshot, flag):
    chain = chain_and_snapshot[0]
    chain.delete(-1)
    chain_and_snapshot = (chain, chain_and_snapshot[2](chain), chain_and_snapshot[2])
    with pytest.raises(InvalidParameterError) as excinfo:
        chain.append(RevoluteJoint(4, 1, math.pi, SE3()), safe=True, **{flag: True})
    check_error(excinfo, ValueError, flag, True)
    assert_unchanged(chain_and_snapshot)


def test_append_after_an_end_tip(chain_and_snapshot):
    with pytest.raises(InvalidParameterError) as excinfo:
        chain_and_snapshot[0].append(RevoluteJoint(4, 1, math.pi, SE3()))
    check_error(excinfo, ValueError, "EndTip")
    assert_unchanged(chain_and_snapshot)


def test_append_a_start_tip(snapshot):
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    before = snapshot(chain)
    with pytest.raises(InvalidParameterError) as excinfo:
        chain.append(StartTip(4, 1, SE3(), 1.5))
    check_error(excinfo, ValueError, "StartTip")
    assert snapshot(chain) == before


def test_append_not_a_joint(snapshot):
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    before = snapshot(chain)
    with pytest.raises(InvalidTypeError) as excinfo:
        chain.append(SE3.Trans(1, 0, 0))
    check_error(excinfo, TypeError, "Joint", "SE3")
    assert snapshot(chain) == before


@pytest.mark.parametrize("flag", ["relative", "safe", "fixedPosition", "fixedOrientation"])
def test_append_flags_must_be_booleans(snapshot, flag):
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    before = snapshot(chain)
    with pytest.raises(InvalidTypeError) as excinfo:
        chain.append(RevoluteJoint(4, 1, math.pi, SE3()), **{flag: "yes"})
    check_error(excinfo, TypeError, flag, "yes")
    assert snapshot(chain) == before


#: method name -> call with a joint index
INDEXED_CALLS = {
    "transformJoint": lambda c, j: c.transformJoint(j, SE3.Trans(0, 0, 0.1)),
    "translateJointAlongAxisOfMotion": lambda c, j: c.translateJointAlongAxisOfMotion(j, 0.1),
    "rotateJointAboutAxisOfMotion": lambda c, j: c.rotateJointAboutAxisOfMotion(j, 0.1),
    "delete": lambda c, j: c.delete(j),
    "setJointState": lambda c, j: c.setJointState(j, 0.0),
}


@pytest.mark.parametrize("method", INDEXED_CALLS)
@pytest.mark.parametrize("index", [7, 8, 1000, -8, -100])
def test_joint_index_out_of_range(chain_and_snapshot, method, index):
    with pytest.raises(JointIndexError) as excinfo:
        INDEXED_CALLS[method](chain_and_snapshot[0], index)
    check_error(excinfo, IndexError, "jointIndex", index)
    assert_unchanged(chain_and_snapshot)


@pytest.mark.parametrize("method", INDEXED_CALLS)
@pytest.mark.parametrize("index", [1.0, "2", None])
def test_joint_index_not_an_integer(chain_and_snapshot, method, index):
    with pytest.raises(InvalidTypeError) as excinfo:
        INDEXED_CALLS[method](chain_and_snapshot[0], index)
    check_error(excinfo, TypeError, "jointIndex", index)
    assert_unchanged(chain_and_snapshot)


@pytest.mark.parametrize("method", INDEXED_CALLS)
def test_negative_index_counts_from_the_end(example_1a_factory, snapshot, method):
    a, b = example_1a_factory(), example_1a_factory()
    assert INDEXED_CALLS[method](a, -3) == INDEXED_CALLS[method](b, 4)
    assert snapshot(a) == snapshot(b)


@pytest.mark.parametrize("value", [NAN, INF, -INF])
@pytest.mark.parametrize(
    "call, name",
    [
        (lambda c, v: c.translateJointAlongAxisOfMotion(4, v), "distance"),
        (lambda c, v: c.rotateJointAboutAxisOfMotion(4, v), "angle"),
        (lambda c, v: c.setJointState(4, v), "newState"),
        (lambda c, v: c.setJointStates([0, 0, v, 0, 0, 0, 0]), "states[2]"),
    ],
    ids=["distance", "angle", "state", "states"],
)
def test_non_finite_numbers(chain_and_snapshot, call, name, value):
    with pytest.raises(InvalidParameterError) as excinfo:
        call(chain_and_snapshot[0], value)
    check_error(excinfo, ValueError, name, value)
    assert_unchanged(chain_and_snapshot)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda c: c.translateJointAlongAxisOfMotion(4, "1"), "distance"),
        (lambda c: c.rotateJointAboutAxisOfMotion(4, None), "angle"),
        (lambda c: c.setJointState(4, True), "newState"),
    ],
    ids=["distance", "angle", "state"],
)
def test_numbers_of_the_wrong_type(chain_and_snapshot, call, name):
    with pytest.raises(InvalidTypeError) as excinfo:
        call(chain_and_snapshot[0])
    check_error(excinfo, TypeError, name)
    assert_unchanged(chain_and_snapshot)


@pytest.mark.parametrize("states", [[0.0] * 6, [0.0] * 8, []])
def test_set_joint_states_needs_one_value_per_joint(chain_and_snapshot, states):
    with pytest.raises(InvalidParameterError) as excinfo:
        chain_and_snapshot[0].setJointStates(states)
    check_error(excinfo, ValueError, "states", len(states))
    assert_unchanged(chain_and_snapshot)


@pytest.mark.parametrize("case", BAD_POSES)
@pytest.mark.parametrize("method", ["transformJoint", "transformAll"])
def test_transformation_not_a_rigid_transform(chain_and_snapshot, case, method):
    make, error, fragment = BAD_POSES[case]
    chain = chain_and_snapshot[0]
    with pytest.raises(error) as excinfo:
        if method == "transformJoint":
            chain.transformJoint(4, make())
        else:
            chain.transformAll(make())
    check_error(
        excinfo,
        ValueError if error is InvalidParameterError else TypeError,
        "Transformation",
        fragment,
    )
    assert_unchanged(chain_and_snapshot)


@pytest.mark.parametrize(
    "call",
    [
        lambda c: c.translateJointAlongAxisOfMotion(4, 0.1, propogate=False, propagate=True),
        lambda c: c.rotateJointAboutAxisOfMotion(4, 0.1, propogate=False, propagate=True),
        lambda c: c.transformJoint(4, SE3(), propogate=False, propagate=True),
    ],
    ids=["translate", "rotate", "transform"],
)
def test_contradicting_propagate_spellings(chain_and_snapshot, call):
    with pytest.raises(InvalidParameterError) as excinfo:
        call(chain_and_snapshot[0])
    check_error(excinfo, ValueError, "propagate", True)
    check_error(excinfo, ValueError, "propogate", False)
    assert_unchanged(chain_and_snapshot)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda c: c.translateJointAlongAxisOfMotion(4, 0.1, propogate="no"), "propogate"),
        (lambda c: c.rotateJointAboutAxisOfMotion(4, 0.1, propagate=0), "propagate"),
        (
            lambda c: c.translateJointAlongAxisOfMotion(4, 0.1, applyToPreviousWaypoint=1),
            "applyToPreviousWaypoint",
        ),
    ],
    ids=["propogate", "propagate", "applyToPreviousWaypoint"],
)
def test_edit_flags_must_be_booleans(chain_and_snapshot, call, name):
    with pytest.raises(InvalidTypeError) as excinfo:
        call(chain_and_snapshot[0])
    check_error(excinfo, TypeError, name)
    assert_unchanged(chain_and_snapshot)


def test_the_editors_command_error_is_the_one_in_errors():
    from kinegami.editor.commands import CommandError
    from kinegami.errors import EditorCommandError

    assert CommandError is EditorCommandError
