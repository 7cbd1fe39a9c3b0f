"""Compiled (numba) time-step kernels, one module per stepping solver, and their contract.

A kernel ``advance(st, i, i_stop, dt, *params, every, out, ev)`` advances the state ``st`` in
place from step ``i`` towards ``i_stop``, writes every ``every``-th step into ``out``, records
impacts as rows ``(time or step, body 0/1, v_before, v_after)`` of ``ev``, and returns
``(step reached, status, impacts recorded)`` with a status code below. This package's
``__init__`` holds only plain constants, so importing it does not load numba.
"""

#: A state component beyond this magnitude (m or m/s) counts as blown up.
BIG = 1e150
#: Impacts recorded per kernel call before it hands back to Python.
EVENT_BUFFER = 4096
#: Kernel status codes.
OK, BLOWUP, TUNNEL_A, TUNNEL_B, REST = 0, 1, 2, 3, 4
