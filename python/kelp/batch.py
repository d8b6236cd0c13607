"""kelp.Batch's Python part (issue 27, item 4), if any. Its names in __all__ are re-exported by
the kelp package."""

__all__ = []
