# SPDX-License-Identifier: GPL-3.0-or-later
from ._asperity import *  # noqa: F401,F403
from ._asperity import __version__ as __version__
