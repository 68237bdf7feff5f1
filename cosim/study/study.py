"""The former home of the study code, kept only while ``cosim/cli/app.py`` imports from it.

Import from :mod:`cosim.study` instead; this module goes once the command line does.
"""
from cosim.study import *  # noqa: F401,F403
from cosim.study import __all__  # noqa: F401
