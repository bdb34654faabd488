"""Static steps follow a load's or a prescribed motion's time function, however steep, to the
equilibrium its value at the step's end asks for.

A static path of an elastic structure with one equilibrium per load has its end fixed by the
loads and motions at the end, whatever the time function's shape on the way: a ramp over 1e-12
of the load factor, a table jumping up and back down within an increment. The load-control
predictor took the functions' slope at the increment's start and extrapolated it (a ramp over
1e-6 of the load factor: 5e5 times the load over a 0.5 increment), so steep functions failed
with "Newton did not converge" or a non-finite residual; it now takes their secant over the
increment (crates/tape-core, statics.rs).

Reference: the same value reached by a linear function over the step (for a motion, which
moves its DOF by ``value (f(t) - f(t_on))``, the function's change over the step). The strip (the
plate of `_plate`, 200 x 20 x 1 mm) deflects by 1.5 mm under the 0.2 N corner load and by the
2 mm motion, 1 % of its length: nonlinear but far from any instability, so the equilibrium is
unique. Two paths to it share no iterate; their end states agree to the static Newton
tolerance times the strip's compliance: measured at most 3e-12 of the deflection over 400
random cases. 1e-9 leaves room for round-off without letting a wrong equilibrium (percents)
pass. A load whose end value is below 1 % of its amplitude (but not zero) is left out: 2e-3 N
and less approach the model's force resolution, which the solver refuses by name.
"""

import numpy as np
from _plate import plate
from hypothesis import assume, given
from hypothesis import strategies as st
from property_settings import examples
from tapespring import Outputs, Step, run
from tapespring.analysis import ramp, table

CORNER = 11
OUTPUTS = Outputs(field_interval=1)

# A ramp's span from 1e-12 of the load factor (a jump) to longer than the step.
spans = st.floats(min_value=-12.0, max_value=0.3).map(lambda e: 10.0**e)


@st.composite
def time_functions(draw):
    """(function, its values at 0 and 1): a ramp anywhere in [0, 1], or a table of up to 5
    points with values in [-1, 1] and gaps from 1e-12 on."""
    if draw(st.booleans()):
        start = draw(st.floats(min_value=0.0, max_value=0.9))
        end = start + draw(spans)
        return ramp(start, end), (0.0, min(1.0, (1.0 - start) / (end - start)))
    t = draw(st.floats(min_value=0.0, max_value=0.9))
    points = []
    for _ in range(draw(st.integers(min_value=2, max_value=5))):
        points.append((t, draw(st.floats(min_value=-1.0, max_value=1.0))))
        t += draw(spans)
    times, values = zip(*points, strict=True)
    return table(points), tuple(float(np.interp(t, times, values)) for t in (0.0, 1.0))


def end_state(kind, function, value, increments):
    """The corner's displacement [m] at load factor 1 under `value` (N or m) times `function`."""
    model = plate()
    if kind == "load":
        model.add_load(CORNER, "uz", value, function=function)
    else:
        model.prescribe(CORNER, "uz", value, function=function)
    results = run(model, [Step.static("s", increments=increments)], outputs=OUTPUTS)
    return results.displacements[-1, CORNER]


@examples(ci=30, long=400)
@given(
    kind=st.sampled_from(["load", "motion"]),
    drawn=time_functions(),
    increments=st.integers(min_value=1, max_value=4),
)
def test_a_static_step_reaches_the_end_value_of_any_time_function(kind, drawn, increments):
    function, (at_start, at_end) = drawn
    value = 0.2 if kind == "load" else 2e-3
    if kind == "motion":
        # A motion moves its DOF by value (f(t) - f(t_on)) from where it was when switched on.
        at_end -= at_start
    else:
        assume(at_end == 0 or abs(at_end) >= 0.01)
    got = end_state(kind, function, value, increments)
    # A zero value is no load (refused as such): the end state is then the reference one.
    expected = end_state(kind, "linear", value * at_end, 4) if at_end != 0 else np.zeros(3)
    scale = np.linalg.norm(end_state(kind, "linear", value, 4))
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * scale)
