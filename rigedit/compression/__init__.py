"""Animation compression with a guaranteed error (issue 20): constant tracks dropped, keys
reduced, values quantised, the error measured on virtual vertices in model space and checked
on every frame after decoding. Pure numpy: no Qt, no VTK; above the animation and model
layers, below io (which reads and writes compressed clips)."""
