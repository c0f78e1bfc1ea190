"""Settings the compiled skinning kernels share with the module that compiles them.

A module of its own so that a kernel file (``dqs_kernels``) and the loader
(``skinning_kernels``) both read them without importing each other. numpy-free and numba-free.
"""
__all__ = ["FASTMATH", "DQS_TASK"]

# Reassociation and FMA contraction let LLVM vectorise the blends; no "fast" flags that
# assume finite values or approximate divisions and square roots.
FASTMATH = {"contract", "reassoc", "nsz", "arcp"}

#: Vertices per parallel task of the DQS kernel (a multiple of skinning_simd.DQ_BLOCK): each
#: task allocates its small scratch blocks once.
DQS_TASK = 1024
