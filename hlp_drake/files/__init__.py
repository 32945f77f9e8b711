"""Files: atomic writes and output checks (``atomic``), bounded reading of documents (``documents``),
PNG figures (``plotting``)."""
