"""``prefetch(array, i, ...)``: a hint that ``array[i, ...]`` will be read soon (LLVM's prefetch).

numba has no prefetch, and the fill kernel spends much of its time on one load: for each
sphere of a slice, in file order, its centre and radius, which lie anywhere in arrays of
all the spheres (the frog's 137 k). Asking for the sphere a few places ahead while this one
is drawn hides that wait: 9 % off the frog's kernel (``benchmarks/bench_reconstruct.py``).
The hint never faults and changes no result.
"""

from __future__ import annotations

from llvmlite import ir
from numba import config, types
from numba.core import cgutils
from numba.extending import intrinsic

# the typed-pointer name (LLVM 14, numba 0.59); LLVM with opaque pointers renames it itself (checked on 22)
_NAME = "llvm.prefetch.p0i8"


def _codegen(context, builder, signature, args):
    aryty = signature.args[0]
    ary = context.make_array(aryty)(context, builder, args[0])
    index = [context.cast(builder, a, t, types.intp) for a, t in zip(args[1:], signature.args[1:])]
    ptr = cgutils.get_item_pointer2(context, builder, data=ary.data, shape=cgutils.unpack_tuple(builder, ary.shape),
                                    strides=cgutils.unpack_tuple(builder, ary.strides), layout=aryty.layout,
                                    inds=index, wraparound=False, boundscheck=False)
    ptr = builder.bitcast(ptr, ir.IntType(8).as_pointer())
    i32 = ir.IntType(32)
    fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.VoidType(), [ptr.type, i32, i32, i32]),
                                        _NAME)
    # read (0), keep in all cache levels (3), data cache (1)
    builder.call(fn, [ptr, ir.Constant(i32, 0), ir.Constant(i32, 3), ir.Constant(i32, 1)])
    return context.get_dummy_value()


@intrinsic
def prefetch1(typingctx, array, i):
    """Prefetch ``array[i]``."""
    return types.void(array, i), _codegen


@intrinsic
def prefetch2(typingctx, array, i, j):
    """Prefetch ``array[i, j]``."""
    return types.void(array, i, j), _codegen


if config.DISABLE_JIT:  # the coverage run executes the kernels as Python (make coverage): a hint is nothing there
    def prefetch1(array, i):  # noqa: F811
        """Prefetch ``array[i]`` (pure Python: nothing)."""

    def prefetch2(array, i, j):  # noqa: F811
        """Prefetch ``array[i, j]`` (pure Python: nothing)."""
