"""The numba types shared by the compiled right-hand sides and the stepping kernels.

A right-hand side is ``accel(r, v, gm, acc, p)``: positions and velocities (n, 3),
``G m`` (n,), the output (n, 3) and the parameter vector of the listed effects
(see :mod:`hamilton_orbits.rhs`), all C-contiguous float64.

The clock: ``p``'s last element.  Before every evaluation of a right-hand side
(``accel``, ``extra``, ``augmented``) an integrator writes there the time of the
state it passes, in its own time variable (``s = -t`` in a time-reversed run; the
generated right-hand side turns it back), so that an effect may depend on the
time (:func:`set_clock`).  Each run has its own ``p``
(``hamilton_orbits.rhs.run_parameters``).

The stepping kernels
take it by its addresses (:data:`ADDRESSES`: the compiled function's C wrapper and
its own entry point, two integers) and make the first-class function of
:data:`ACCEL_TYPE` from them inside (:func:`accel_at`), so that each is compiled
once and cached for every right-hand side.

Why addresses and not the function object: numba turns a first-class function
argument into its address on every call through Python (about 4 us, the cost of
four Wisdom-Holman steps of ten bodies), where an array of two integers costs a
tenth of a microsecond; and the function made from its own entry point is called
with numba's calling convention, not through the C wrapper.
"""

from __future__ import annotations

from typing import Any

from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

__all__ = ["ACCEL_SIGNATURE", "ACCEL_TYPE", "ADDRESSES", "F1", "F2", "accel_at",
           "function_at", "set_clock"]

F1 = types.float64[::1]
F2 = types.float64[:, ::1]

#: ``void(r, v, gm, acc, p)``
ACCEL_SIGNATURE = types.void(F2, F2, F1, F2, F1)

#: The first-class function type of a right-hand side.
ACCEL_TYPE = types.FunctionType(ACCEL_SIGNATURE)


#: The addresses of a compiled function, ``[C wrapper, entry point]`` (int64),
#: as :func:`hamilton_orbits.integrators._setup.accel_arg` finds them.
ADDRESSES = types.int64[::1]


def function_at(ftype: types.FunctionType) -> Any:
    """An intrinsic ``at(c_addr, jit_addr)`` that makes the first-class function of
    ``ftype`` whose C wrapper and entry point are at those addresses (numba calls
    the entry point when it is not 0)."""

    @intrinsic
    def at(typingctx: Any, c_addr: Any, jit_addr: Any) -> Any:
        def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
            fn = cgutils.create_struct_proxy(ftype)(context, builder)
            voidptr = context.get_value_type(types.voidptr)
            fn.c_addr = builder.inttoptr(args[0], voidptr)
            fn.py_addr = cgutils.get_null_value(voidptr)
            fn.jit_addr = builder.inttoptr(args[1], voidptr)
            return fn._getvalue()

        return ftype(types.int64, types.int64), codegen

    return at


#: ``accel_at(c_addr, jit_addr)``: the right-hand side at those addresses.
accel_at = function_at(ACCEL_TYPE)


@njit(cache=True, inline="always")
def set_clock(p, t):  # pragma: no cover - compiled
    """Write the time ``t`` of the state about to be evaluated into ``p``'s clock,
    its last element."""
    p[p.shape[0] - 1] = t
