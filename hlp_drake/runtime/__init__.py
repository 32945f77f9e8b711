"""How the program runs: worker processes and signals (``processes``), terminals (``terminal``) and
a package's names imported on first use (``exports``)."""
