"""Model files (robot and scene) of the ``hlp_drake_models`` Drake package; data only."""
