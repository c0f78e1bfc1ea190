"""Skeleton embedding (Baran and Popovic 2007, "Pinocchio"): a template skeleton fitted
inside a closed triangle mesh. Pure numpy/scipy.

>>> from rigedit.embedding import embed_skeleton, cd_j2j
>>> emb = embed_skeleton(vertices, faces, template_skeleton)     # doctest: +SKIP
>>> emb.positions                        # (J, 3), every template joint   # doctest: +SKIP
"""
from .embed import Embedding, EmbeddingError, HintError, embed_skeleton
from .metric import cd_j2j

__all__ = ["embed_skeleton", "Embedding", "EmbeddingError", "HintError", "cd_j2j"]
