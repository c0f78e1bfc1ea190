"""Animation compression with a guaranteed error (issue 20): constant tracks dropped, keys
reduced, values quantised, the error measured on virtual vertices in model space and checked
on every frame after decoding. Pure numpy: no Qt, no VTK; above the animation and model
layers, below io (which reads and writes compressed clips)."""
from .compressed_clip import CompressedClip, KeyedClip
from .error import measure_error
from .pipeline import CompressionResult, check_max_error, compress_clips
from .report import CompressionReport

__all__ = ["compress_clips", "measure_error", "CompressionReport", "CompressionResult",
           "CompressedClip", "KeyedClip", "check_max_error"]
