"""Studies built on the main job (:mod:`fem_twin.stages.pipeline`): the FE against FVM
cross-check (:mod:`~fem_twin.studies.compare`), the paper's calibration studies with
C_f,dev (:mod:`~fem_twin.studies.calibration`, eq 35), the mixed regime against
deterministic rough-surface solutions (:mod:`~fem_twin.studies.verification`), fitting the
twin's unknowns to a measured curve and predicting the next
(:mod:`~fem_twin.studies.fitting`), and the report of a finished run
(:mod:`~fem_twin.studies.report`)."""
