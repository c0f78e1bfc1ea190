"""Vector (SIMD) building blocks of the compiled skinning kernels, as numba intrinsics.

Imported only by :class:`rigedit.model.skinning_kernels.Kernels` (it imports numba and
llvmlite). numba 0.68 compiles the per-vertex blend of a 3x4 palette as scalar multiply-adds
whatever the source's layout, which made LBS compute-bound at about 10 ns per vertex with four
influences (the FMA units' scalar rate); written here directly as LLVM vector operations on
16-float rows, a vertex's four influences are four 16-wide multiply-adds and the frame runs at
about 3 ns per vertex, about twice the memory-copy floor (measured by
``benchmarks/bench_skinning.py``: 3.1-3.7 ms of CPU for 1M vertices against 1.5 ms for copying
their 56 bytes each). LLVM lowers the 16-wide vectors to whatever the CPU has (AVX-512,
two AVX halves, four SSE quarters).

The palette row of joint ``j`` is its skinning matrix ``K_j`` transposed and flattened:
``row[4 c + i] = K_j[i, c]`` (column ``c`` of the 4x4), so the blended matrix's columns are four
4-float slices and ``K · (x, y, z, 1)`` is three vector multiply-adds.
"""
from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.extending import intrinsic

__all__ = ["blend_apply4", "blend_apply4_normal", "dq_blend4", "ROW"]

ROW = 16  # floats per palette row
_F32 = ir.FloatType()
_I32 = ir.IntType(32)
_I64 = ir.IntType(64)
_ROW = ir.VectorType(_F32, ROW)
_COL = ir.VectorType(_F32, 4)
_FAST = ("fast",)


def _splat(builder, value, vector_type):
    undef = ir.Constant(vector_type, ir.Undefined)
    one = builder.insert_element(undef, value, ir.Constant(_I32, 0))
    mask = ir.Constant(ir.VectorType(_I32, vector_type.count), [0] * vector_type.count)
    return builder.shuffle_vector(one, undef, mask)


def _blend(context, builder, signature, args):
    """Sum of weight_k * row(joint_k) for the 4 (joint, weight) pairs in args[1:9]."""
    palette = context.make_array(signature.args[0])(context, builder, args[0])
    acc = None
    for joint, weight in zip(args[1:5], args[5:9]):
        if joint.type.width < 64:
            joint = builder.sext(joint, _I64)
        address = builder.gep(palette.data, [builder.mul(joint, ir.Constant(_I64, ROW))])
        row = builder.load(builder.bitcast(address, _ROW.as_pointer()), align=4)
        term = builder.fmul(row, _splat(builder, weight, _ROW), flags=_FAST)
        acc = term if acc is None else builder.fadd(acc, term, flags=_FAST)
    return acc


def _column(builder, blended, c):
    mask = ir.Constant(ir.VectorType(_I32, 4), [4 * c + i for i in range(4)])
    return builder.shuffle_vector(blended, blended, mask)


def _combine(builder, blended, xyz, base=None):
    """base + col0 * x + col1 * y + col2 * z as a 4-float vector."""
    r = base
    for c, s in enumerate(xyz):
        term = builder.fmul(_column(builder, blended, c), _splat(builder, s, _COL), flags=_FAST)
        r = term if r is None else builder.fadd(r, term, flags=_FAST)
    return r


def _signature(palette, n_extra, n_out):
    f32 = types.float32
    return types.UniTuple(f32, n_out)(palette, *([types.int32] * 4), *([f32] * 4),
                                      *([f32] * n_extra))


@intrinsic
def blend_apply4(typingctx, palette, j0, j1, j2, j3, w0, w1, w2, w3, x, y, z):
    """(x', y', z') = (sum_k w_k K_jk) · (x, y, z, 1) for four influences (float32)."""
    sig = _signature(palette, 3, 3)

    def codegen(context, builder, signature, args):
        blended = _blend(context, builder, signature, args)
        r = _combine(builder, blended, args[9:12], base=_column(builder, blended, 3))
        out = [builder.extract_element(r, ir.Constant(_I32, i)) for i in range(3)]
        return context.make_tuple(builder, signature.return_type, out)

    return sig, codegen


@intrinsic
def blend_apply4_normal(typingctx, palette, j0, j1, j2, j3, w0, w1, w2, w3, x, y, z, nx, ny,
                        nz):
    """:func:`blend_apply4` plus the blended 3x3 times (nx, ny, nz), not normalised:
    (x', y', z', nx', ny', nz')."""
    sig = _signature(palette, 6, 6)

    def codegen(context, builder, signature, args):
        blended = _blend(context, builder, signature, args)
        p = _combine(builder, blended, args[9:12], base=_column(builder, blended, 3))
        n = _combine(builder, blended, args[12:15])
        out = [builder.extract_element(v, ir.Constant(_I32, i)) for v in (p, n) for i in range(3)]
        return context.make_tuple(builder, signature.return_type, out)

    return sig, codegen


_DQ = ir.VectorType(_F32, 8)


@intrinsic
def dq_blend4(typingctx, dq, signs, pivot, j0, j1, j2, j3, w0, w1, w2, w3):
    """sum_k s_k w_k dq[j_k] for four influences, a dual quaternion as 8 floats (not
    normalised), with s_k = signs[pivot, j_k]: -1 when dq[j_k]'s real part points away from
    dq[pivot]'s (the antipodality flip), else 1. dq is (J, 8) float32: real (x, y, z, w), then
    dual; signs (J, J) float32, computed once per frame (a table lookup per influence instead
    of a 4-term dot product and a compare)."""
    f32 = types.float32
    sig = types.UniTuple(f32, 8)(dq, signs, pivot, *([types.int32] * 4), *([f32] * 4))

    def codegen(context, builder, signature, args):
        table = context.make_array(signature.args[0])(context, builder, args[0])
        sign_table = context.make_array(signature.args[1])(context, builder, args[1])
        n_joints = builder.extract_value(sign_table.shape, 1)

        def wide(joint):
            return joint if joint.type.width == 64 else builder.sext(joint, _I64)

        sign_row = builder.mul(wide(args[2]), n_joints)
        acc = None
        for joint, weight in zip(args[3:7], args[7:11]):
            joint = wide(joint)
            address = builder.gep(table.data, [builder.mul(joint, ir.Constant(_I64, 8))])
            q = builder.load(builder.bitcast(address, _DQ.as_pointer()), align=4)
            sign = builder.load(builder.gep(sign_table.data, [builder.add(sign_row, joint)]))
            signed = builder.fmul(weight, sign, flags=_FAST)
            term = builder.fmul(q, _splat(builder, signed, _DQ), flags=_FAST)
            acc = term if acc is None else builder.fadd(acc, term, flags=_FAST)
        out = [builder.extract_element(acc, ir.Constant(_I32, i)) for i in range(8)]
        return context.make_tuple(builder, signature.return_type, out)

    return sig, codegen
