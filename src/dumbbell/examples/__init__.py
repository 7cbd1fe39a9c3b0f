"""Examples of :mod:`dumbbell.spaces` on spaces that are not dumbbells, each runnable as
``python -m dumbbell.examples.NAME``: it writes a GIF with energy bars and prints the step-size
guard's report and what it measured.

- ``newtons_cradle``: five elastic balls on pins; energy and momentum pass along the row;
- ``pendulum``: a physical pendulum on a ``DampedRotarySpring``; its period against the
  small-angle formula;
- ``slope``: a box sliding and tumbling down a slope with friction; the heat counter closes
  the energy balance.
"""
