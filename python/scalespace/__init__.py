from ._scalespace import *  # noqa: F401,F403
