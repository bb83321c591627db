"""The package version, in one place (read by ``kinegami.__init__`` and the exporters).

It is the ``version`` of pyproject.toml; a test checks that the two agree.
"""

__version__ = "0.1.0"
