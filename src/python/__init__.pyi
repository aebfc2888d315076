# SPDX-License-Identifier: GPL-3.0-or-later
from os import PathLike
from typing import Any, Union

from ._asperity import *  # noqa: F401,F403
from ._asperity import __version__ as __version__

def read_cor_table(path: Union[str, "PathLike[str]"]) -> dict[str, Any]:
    """A written restitution table (path ending in .csv, its .json beside it) as cor_table() returns it."""
