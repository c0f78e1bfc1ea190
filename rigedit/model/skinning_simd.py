"""Vector (SIMD) building blocks of the compiled skinning kernels, as numba intrinsics.

Imported only by the kernels' sources (:mod:`.lbs_kernels`, :mod:`.dqs_kernels`; it imports
numba and llvmlite). numba 0.68 compiles the per-vertex blend of a 3x4 palette as scalar
multiply-adds whatever the source's layout, which made LBS compute-bound at about 10 ns per
vertex with four influences (the FMA units' scalar rate); written here directly as LLVM
vector operations on 16-float rows, a vertex's four influences are four 16-wide multiply-adds
and the frame runs at about 3 ns per vertex, about twice the memory-copy floor (measured by
``benchmarks/bench_skinning.py``: 3.1-3.7 ms of CPU for 1M vertices against 1.5 ms for copying
their 56 bytes each). LLVM lowers the 16-wide vectors to whatever the CPU has (AVX-512,
two AVX halves, four SSE quarters).

numba's on-disk cache of a kernel follows the kernel's own source file, not this one: the
kernels' files (:mod:`.lbs_kernels`, :mod:`.dqs_kernels`) name this file's sha256 as
``SIMD_SHA256``; after editing this file, put its new hash there (the test
``test_the_kernel_sources_name_these_vector_blocks`` prints it), which rebuilds their caches.

The palette row of joint ``j`` is its skinning matrix ``K_j`` transposed and flattened:
``row[4 c + i] = K_j[i, c]`` (column ``c`` of the 4x4), so the blended matrix's columns are four
4-float slices and ``K · (x, y, z, 1)`` is three vector multiply-adds.
"""
from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

__all__ = ["blend_apply4", "blend_apply4_normal", "dq_blend4_into", "dq_apply16",
           "dq_apply16_normals", "ROW", "DQ_BLOCK"]

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
#: Vertices one :func:`dq_apply16` transforms: one 16-float vector per coordinate.
DQ_BLOCK = 16


def _wide(builder, index):
    return index if index.type.width == 64 else builder.sext(index, _I64)


def _rows(context, builder, array_type, array, row, width, n_floats):
    """Pointer to ``array[row, 0]`` of a C-contiguous float32 array of rows of ``width`` floats,
    as a pointer to a vector of ``n_floats``."""
    data = context.make_array(array_type)(context, builder, array).data
    address = builder.gep(data, [builder.mul(_wide(builder, row), ir.Constant(_I64, width))])
    return builder.bitcast(address, ir.VectorType(_F32, n_floats).as_pointer())


def _mask(indices):
    return ir.Constant(ir.VectorType(_I32, len(indices)), list(indices))


@intrinsic
def dq_blend4_into(typingctx, dq, signs, pivot, j0, j1, j2, j3, w0, w1, w2, w3, blend, row,
                   accumulate):
    """blend[row] = (or += when ``accumulate``) sum_k s_k w_k dq[j_k] for four influences, a
    dual quaternion as 8 floats (not normalised), with s_k = signs[pivot, j_k]: -1 when
    dq[j_k]'s real part points away from dq[pivot]'s (the antipodality flip), else 1.

    dq (J, 8) float32: real (x, y, z, w), then dual; signs (J, J) float32, computed once per
    frame (a table lookup per influence instead of a 4-term dot product and a compare); blend
    (DQ_BLOCK, 8) float32, written with one 8-float store."""
    f32 = types.float32
    sig = types.none(dq, signs, pivot, *([types.int32] * 4), *([f32] * 4), blend, row,
                     accumulate)

    def codegen(context, builder, signature, args):
        table = context.make_array(signature.args[0])(context, builder, args[0])
        sign_table = context.make_array(signature.args[1])(context, builder, args[1])
        n_joints = builder.extract_value(sign_table.shape, 1)
        sign_row = builder.mul(_wide(builder, args[2]), n_joints)
        acc = None
        for joint, weight in zip(args[3:7], args[7:11]):
            joint = _wide(builder, joint)
            address = builder.gep(table.data, [builder.mul(joint, ir.Constant(_I64, 8))])
            q = builder.load(builder.bitcast(address, _DQ.as_pointer()), align=4)
            sign = builder.load(builder.gep(sign_table.data, [builder.add(sign_row, joint)]))
            signed = builder.fmul(weight, sign, flags=_FAST)
            term = builder.fmul(q, _splat(builder, signed, _DQ), flags=_FAST)
            acc = term if acc is None else builder.fadd(acc, term, flags=_FAST)
        target = _rows(context, builder, signature.args[11], args[11], args[12], 8, 8)
        with builder.if_else(args[13]) as (add, first):
            with add:
                builder.store(builder.fadd(builder.load(target, align=4), acc, flags=_FAST),
                              target, align=4)
            with first:
                builder.store(acc, target, align=4)
        return context.get_dummy_value()

    return sig, codegen


class _Vec:
    """16-float vector arithmetic on an IR builder (fast-math flags as the blends use)."""

    def __init__(self, builder):
        self.b = builder

    def mul(self, a, b):
        return self.b.fmul(a, b, flags=_FAST)

    def add(self, a, b):
        return self.b.fadd(a, b, flags=_FAST)

    def sub(self, a, b):
        return self.b.fsub(a, b, flags=_FAST)

    def div(self, a, b):
        # An exact division (no reciprocal approximation), as numba's FASTMATH allows.
        return self.b.fdiv(a, b, flags=("arcp", "contract", "reassoc", "nsz"))

    def const(self, value):
        return _splat(self.b, ir.Constant(_F32, value), ir.VectorType(_F32, DQ_BLOCK))

    def cross_plus(self, r, w, p):
        """r x p + w p, per component."""
        (r0, r1, r2), (x, y, z) = r, p
        return (self.add(self.sub(self.mul(r1, z), self.mul(r2, y)), self.mul(w, x)),
                self.add(self.sub(self.mul(r2, x), self.mul(r0, z)), self.mul(w, y)),
                self.add(self.sub(self.mul(r0, y), self.mul(r1, x)), self.mul(w, z)))

    def rotate(self, r, w, two, p, t=(None, None, None)):
        """p + two (r x (r x p + w p) + t): with two = 2 / |(r, w)|^2 the rotation of the
        unnormalised quaternion (r, w) applied to p, plus 2 t / |(r, w)|^2."""
        (r0, r1, r2), (cx, cy, cz) = r, self.cross_plus(r, w, p)
        out = []
        for k, rc in enumerate((self.sub(self.mul(r1, cz), self.mul(r2, cy)),
                                self.sub(self.mul(r2, cx), self.mul(r0, cz)),
                                self.sub(self.mul(r0, cy), self.mul(r1, cx)))):
            if t[k] is not None:
                rc = self.add(rc, t[k])
            out.append(self.add(p[k], self.mul(two, rc)))
        return out


def _load_xyz(context, builder, array_type, array, row):
    """x, y, z of 16 rows of an (N, 3) float32 array from ``row`` on, as three vectors."""
    pts = builder.load(_rows(context, builder, array_type, array, row, 3, 3 * DQ_BLOCK),
                       align=4)
    return [builder.shuffle_vector(pts, pts, _mask(range(c, 3 * DQ_BLOCK, 3)))
            for c in range(3)]


def _store_xyz(context, builder, array_type, array, row, xyz):
    """Interleave three 16-float vectors back into 16 rows of 3 from ``row`` on."""
    n = DQ_BLOCK
    xy = builder.shuffle_vector(xyz[0], xyz[1], _mask(range(2 * n)))
    zz = builder.shuffle_vector(xyz[2], xyz[2], _mask(list(range(n)) * 2))
    rows = builder.shuffle_vector(xy, zz, _mask([c * n + i for i in range(n) for c in range(3)]))
    builder.store(rows, _rows(context, builder, array_type, array, row, 3, 3 * n), align=4)


def _dq_apply(context, builder, signature, args, normals):
    """Code of :func:`dq_apply16` (args blend, points, p0, out, v0) and, with ``normals``, of
    :func:`dq_apply16_normals` (args blend, points, p0, rest normals, out, out normals, v0)."""
    v = _Vec(builder)
    rows = builder.load(_rows(context, builder, signature.args[0], args[0],
                              ir.Constant(_I64, 0), 8, 8 * DQ_BLOCK), align=4)
    # De-interleave: component c of the 16 blends.
    b0, b1, b2, b3, e0, e1, e2, e3 = (
        builder.shuffle_vector(rows, rows, _mask(range(c, 8 * DQ_BLOCK, 8))) for c in range(8))
    r, w, d = (b0, b1, b2), b3, (e0, e1, e2)
    two = v.div(v.const(2.0), v.add(v.add(v.mul(b0, b0), v.mul(b1, b1)),
                                    v.add(v.mul(b2, b2), v.mul(b3, b3))))
    # t = w d - e r + r x d (unnormalised: every term is quadratic in the blend)
    t = [v.add(v.sub(v.mul(w, d[k]), v.mul(e3, r[k])), rd)
         for k, rd in enumerate(v.cross_plus(r, v.const(0.0), d))]
    points = _load_xyz(context, builder, signature.args[1], args[1], args[2])
    out_index = 4 if normals else 3
    _store_xyz(context, builder, signature.args[out_index], args[out_index], args[-1],
               v.rotate(r, w, two, points, t))
    if normals:
        rest = _load_xyz(context, builder, signature.args[3], args[3], args[2])
        nx, ny, nz = v.rotate(r, w, two, rest)
        # Renormalised: exact for rotations already, needed after a blended scale.
        length = v.add(v.add(v.mul(nx, nx), v.mul(ny, ny)), v.mul(nz, nz))
        sqrt = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(length.type, [length.type]),
            f"llvm.sqrt.v{DQ_BLOCK}f32")
        inv = v.div(v.const(1.0), builder.call(sqrt, [length]))
        _store_xyz(context, builder, signature.args[5], args[5], args[-1],
                   [v.mul(nx, inv), v.mul(ny, inv), v.mul(nz, inv)])
    return context.get_dummy_value()


@intrinsic
def dq_apply16(typingctx, blend, points, p0, out, v0):
    """out[v0 : v0 + 16] = points[p0 : p0 + 16] moved by the blended dual quaternions
    blend[0 : 16] (DQ_BLOCK rows of 8 floats as :func:`dq_blend4_into` leaves them, not
    normalised), 16 vertices at a time: each of the 8 blend components and each coordinate
    is one 16-float vector, so the transform's 50-odd operations are shared by 16 vertices.

    With the blend (r, w; d, e) normalised by |(r, w)|: p' = p + 2 r x (r x p + w p)
    + 2 (w d - e r + r x d). Every term is quadratic in the blend, so the normalisation is one
    factor 2 / |(r, w)|^2 (no square root). points and out (N, 3) float32."""
    def codegen(context, builder, signature, args):
        return _dq_apply(context, builder, signature, args, normals=False)

    return types.none(blend, points, p0, out, v0), codegen


@intrinsic
def dq_apply16_normals(typingctx, blend, points, p0, normals, out, out_normals, v0):
    """:func:`dq_apply16` plus the normals: normals[p0 : p0 + 16] turned by the blend's
    rotation and renormalised into out_normals[v0 : v0 + 16] (normals (N, 3) float32, read
    from the same rows as the points)."""
    def codegen(context, builder, signature, args):
        return _dq_apply(context, builder, signature, args, normals=True)

    return types.none(blend, points, p0, normals, out, out_normals, v0), codegen
