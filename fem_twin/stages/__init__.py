"""The stages of the main job, each usable on its own: the virtual geometry and the pin
levelling (:mod:`~fem_twin.stages.geometry`), the flow factors of every patch pair
(:mod:`~fem_twin.stages.factors`), the Stribeck curves with their band, plots, fields and
results (:mod:`~fem_twin.stages.curves`), whose sweeps run as tasks on the workers
(:mod:`~fem_twin.stages.sweeps`); what each depends on
(:mod:`~fem_twin.stages.provenance`).  :func:`fem_twin.stages.pipeline.run` orders them."""
