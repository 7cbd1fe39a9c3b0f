"""A check's finding: what the step-size guard reports of one spring, body, setting or
constraint (:class:`Finding`; public as ``dumbbell.spaces.Finding``)."""

from __future__ import annotations

from dataclasses import dataclass

#: No public names here: ``Finding`` is :mod:`dumbbell.spaces.guard`'s.
__all__: list[str] = []

#: The relation a good value keeps to its limit, and the one a failing value shows.
_FAILS = {"<": ">=", "<=": ">", ">=": "<"}
#: What a kind's value is, where its number alone would not say.
_QUANTITY = {"spring": "w dt = ", "rotary-spring": "w dt = ", "spring-network": "w dt = "}


@dataclass(frozen=True)
class Finding:
    """One check: ``kind`` (spring, rotary-spring, spring-network, tunnelling, slop, bias,
    threads, joint, state), the ``subject`` it is about, the measured ``value`` and its
    ``limit`` (w*dt for springs, length units moved per step for tunnelling, length units for
    slop, the bias for bias, the number of threads for threads), the ``relation`` a good
    value keeps to the limit ('<', '<=' or '>='; 'finite' for a state no step fixes), the
    ``fix`` with its reason in words, the largest step that clears it, ``dt_max`` (s; None
    when no step can), and the ``unit`` of value and limit ('' if none).
    A constraint's row (kind ``joint``) may instead be ``relation`` 'measured' (a number
    with no limit: a motor's work, a loss the step does not change; ok) or 'unchecked' (not
    measured: ``fix`` says why; not ok, and not a failure :func:`check` lists); ``note`` says
    in words what the number is.

    Parameters
    ----------
    kind : str
        What is checked.
    subject : str
        What it is about.
    value, limit : float
        The measured value and its limit.
    fix : str
        The fix, with its reason in words.
    dt_max : float or None, default None
        The largest step that clears it (None when no step can).
    relation : str, default '<'
        What a good value keeps to the limit.
    unit : str, default ''
        The unit of value and limit.
    note : str, default ''
        What else the row says.

    Examples
    --------
    >>> from dumbbell.spaces import Finding        # a row of the guard's, made by hand
    >>> f = Finding("spring", "DampedSpring 0", 0.7454, 0.00995, "take dt < 0.0002225 s",
    ...             0.0002225)
    >>> f.ok, f.checked, f.comparison()
    (False, True, 'w dt = 0.7454 >= 0.00995')
    >>> print(f)
    spring: DampedSpring 0: w dt = 0.7454 >= 0.00995; take dt < 0.0002225 s
    """

    kind: str
    subject: str
    value: float
    limit: float
    fix: str
    dt_max: float | None = None
    relation: str = "<"
    unit: str = ""
    note: str = ""

    @property
    def checked(self) -> bool:
        """Whether the row was measured (False: 'unchecked')."""
        return self.relation != "unchecked"

    @property
    def ok(self) -> bool:
        """Whether the value keeps its relation to the limit."""
        if self.relation == "measured":
            return True
        if self.relation == "<":
            return self.value < self.limit
        if self.relation == "<=":
            return self.value <= self.limit
        if self.relation == ">=":
            return self.value >= self.limit
        return False

    def comparison(self) -> str:
        """'value relation limit' with the relation that holds, the numbers printed with
        enough digits to show it.

        Returns
        -------
        str
            'value relation limit', e.g. ``'w dt = 0.7454 >= 0.00995'``.
        """
        unit = f" {self.unit}" if self.unit else ""
        if self.relation == "measured":
            return f"{self.value:.4g}{unit}"
        if self.relation not in _FAILS:
            return ""
        rel = self.relation if self.ok else _FAILS[self.relation]
        a, b = _distinct(self.value, self.limit, rel)
        return f"{_QUANTITY.get(self.kind, '')}{a}{unit} {rel} {b}{unit}"

    def __str__(self) -> str:
        shown = self.comparison()
        return f"{self.kind}: {self.subject}: {shown + '; ' if shown else ''}{self.fix}"


def _distinct(a: float, b: float, rel: str) -> tuple[str, str]:
    """``a`` and ``b`` printed with the fewest digits (4 or more) that keep ``rel`` true of
    the printed numbers."""
    holds = {"<": float.__lt__, "<=": float.__le__, ">=": float.__ge__, ">": float.__gt__}[rel]
    for digits in range(4, 18):
        x, y = f"{a:.{digits}g}", f"{b:.{digits}g}"
        if holds(float(x), float(y)):
            return x, y
    return repr(a), repr(b)
