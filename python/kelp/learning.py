"""The gym-style learning environment (issue 27, item 5). Its names in __all__ are re-exported by
the kelp package."""

__all__ = []
