"""fmutrace: replay CSV traces through FMI 2 / FMI 3 co-simulation FMUs
with fmpy and report where they differ from reference traces."""
