"""The namespace of the docstring examples in kinegami/ (pytest runs them with
--doctest-modules): what ``from kinegami import *`` gives, plus numpy as ``np``, as in the
paper's listings."""

import numpy as np
import pytest


@pytest.fixture(autouse=True)
def _kinegami_namespace(doctest_namespace):
    import kinegami

    doctest_namespace["np"] = np
    for name in kinegami.__all__:
        doctest_namespace[name] = getattr(kinegami, name)
