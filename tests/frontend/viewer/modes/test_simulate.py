"""Simulate mode (frontend/viewer/modes/simulate.py) in a browser's view of the service's 3D view:
presets and sliders without feedback loops, half-typed values kept from the simulator, the gait
readout, and a climb that ends at the floor."""

import pytest

from frontend.viewer.modes.gait_search import GAIT_PRESETS
from frontend.viewer.viser_adapter import slider_marks
from sim_core.climb.records import ClimbEnd
from tests.frontend.viewer.view_service import wait_for


def test_presets_and_sliders_do_not_feed_back(browsers):
    _, session = browsers()
    simulate = session.modes["simulate"]
    name = list(GAIT_PRESETS)[2]
    simulate.set_preset(name)
    assert simulate.gui_preset.value == name, "setting the sliders from a preset does not mark it custom"
    assert not simulate.gui_symmetric.value and simulate.gui_zeta0_right.value == pytest.approx(0.9505)
    controls = simulate.controls()
    assert (controls.left.zeta0, controls.right.zeta0, controls.right.psi0_deg) == (0.90, 0.9505, pytest.approx(35))
    wait_for(lambda: simulate.gait is not None and simulate.gait_note != "searching…")
    assert simulate.gait.period == 4 and simulate.gait.stable, simulate.gait_note
    simulate.gui_zeta0_left.value = 0.88  # as if a person moved it (the callback runs)
    assert simulate.gui_preset.value == "custom"
    simulate.gui_symmetric.value = True
    assert simulate.gui_zeta0_right.value == 0.88 and simulate.gui_zeta0_right.disabled
    assert simulate.climb.controls.right.zeta0 == 0.88


def test_half_typed_values_never_reach_the_simulator(browsers):
    _, session = browsers()
    simulate = session.modes["simulate"]
    wait_for(lambda: simulate.gait_note != "searching…")
    in_use = simulate.climb.controls
    # Under the session's lock, as the view's own loop draws: a frame drawn from this thread beside
    # the loop's raced it for the scene's nodes ("removed BoxHandle", once on a loaded machine).
    with session.lock:
        half_typed = ((simulate.gui_psi0_left, 0.0), (simulate.gui_zeta0_left, 0.9999), (simulate.gui_gravity, 0))
        for handle, typed in half_typed:
            whole = handle.value
            handle.value = typed  # what a number box sends on the way to a whole value
            assert simulate.climb.controls == in_use, handle.label
            assert handle.label in simulate.input_note and "must be" in simulate.input_note
            assert "**Not used:**" in simulate.readout(60.0)
            handle.value = whole  # typed to the end
            assert simulate.input_note is None and simulate.climb.controls == in_use
        simulate.gui_speed.value, before = -3.0, simulate.time
        simulate.frame(0.1)
    assert simulate.time > before, "a half-typed speed leaves the speed in use, never backwards"


def test_a_value_typed_past_a_sliders_end_is_refused_not_held_to_the_end(browsers):
    """psi0 80 typed in its box became 60 and was used: the browser holds a slider's box to the
    slider's ends when it loses focus. Now the slider reaches one step past the range (its marks
    at 15 and 60), so what comes is 60.5: not used, and the readout names the slider, its range
    and what was typed; a value in range is used at once."""
    browser, session = browsers()
    simulate = session.modes["simulate"]
    wait_for(lambda: simulate.gait_note != "searching…")
    in_use = simulate.climb.controls
    psi0 = simulate.gui_psi0_left
    assert (psi0.min, psi0.max, slider_marks(psi0)) == (14.5, 60.5, ((15.0, "15"), (60.0, "60")))
    browser.set_gui("psi0 L [°]", 80.0)  # typed
    wait_for(lambda: "got 80" in (simulate.input_note or ""))
    browser.set_gui("psi0 L [°]", psi0.max)  # the box left: the browser holds it to the slider's end
    wait_for(lambda: psi0.value == psi0.max)
    assert simulate.climb.controls == in_use, "60 is not used in place of 80"
    readout = simulate.readout(60.0)
    assert "**Not used:** psi0 L [°] must be 15 to 60, got 80" in readout, readout
    browser.set_gui("psi0 L [°]", 5.0)
    wait_for(lambda: "got 5" in (simulate.input_note or ""))
    browser.set_gui("psi0 L [°]", psi0.min)
    wait_for(lambda: psi0.value == psi0.min)
    assert simulate.climb.controls == in_use and "psi0 L [°] must be 15 to 60, got 5" in simulate.readout(60.0)
    # (Replay mode's speed slider has the same label: this one is set as its callback would be.)
    simulate.gui_speed.value = 9.0
    simulate.gui_speed.value = simulate.gui_speed.max
    assert simulate.speed == 1.0 and "speed [×] must be 0.1 to 4, got 9" in simulate.readout(60.0)
    browser.set_gui("psi0 L [°]", 40.0)
    wait_for(lambda: simulate.climb.controls.left.psi0_deg == pytest.approx(40.0))
    assert "psi0 L" not in simulate.readout(60.0)


def test_simulate_mode_stops_a_descending_climb_at_the_floor_and_says_so(browsers):
    _, session = browsers()
    simulate = session.modes["simulate"]
    wait_for(lambda: simulate.gait_note != "searching…")  # the first search, which restarts the climb
    simulate.gui_psi0_left.value = 30.0
    simulate.gui_zeta0_left.value = 0.99  # beyond jumping in place: the gait descends
    wait_for(lambda: simulate.gait_note != "searching…")
    with session.lock:
        simulate.restart()
        simulate.playback("Pause")
        simulate.time = 300.0
        simulate.frame(0.0)
        readout = simulate.readout(60.0)
    assert simulate.climb.current.failure is ClimbEnd.FLOOR
    assert "**Failure:** **floor** at jump" in readout and "the body reached the chute's floor" in readout, readout
    assert "height** 0.000 m" in readout, readout


@pytest.mark.parametrize("name", ["lqr", "deadbeat", "placement"])
def test_a_controller_holds_the_height_a_browser_chose_and_the_readout_shows_its_command(browsers, name):
    browser, session = browsers()
    other = browsers()[1].modes["simulate"]  # a second browser's view keeps its own open loop
    simulate = session.modes["simulate"]
    wait_for(lambda: simulate.gait_note != "searching…")
    browser.set_gui("target [m]", 0.45)
    browser.set_gui("Controller", name)
    wait_for(lambda: simulate.law_note == f"{name} holding 0.45 m", timeout=30)
    with session.lock:
        simulate.playback("Pause")
        simulate.time = 25.0  # about 70 jumps of the paper's robot
        simulate.frame(0.0)
        readout = simulate.readout(60.0)
    assert simulate.climb.current.failure is None
    heights = [plan.jump.start.body_height for plan in simulate.climb.plans[-10:]]
    assert max(abs(height - 0.45) for height in heights) < 0.01, heights
    assert f"**Controller:** {name} holding 0.45 m · touchdown" in readout and "→ psi0" in readout, readout
    assert other.climb.law is None and "off: the sliders set the legs" in other.readout(60.0)
    browser.set_gui("Controller", "off")
    wait_for(lambda: simulate.climb.law is None and simulate.law_note.startswith("off"))


def test_a_target_out_of_the_chute_is_not_used_and_says_why(browsers):
    browser, session = browsers()
    simulate = session.modes["simulate"]
    wait_for(lambda: simulate.gait_note != "searching…")
    browser.set_gui("Controller", "pid")
    wait_for(lambda: simulate.law_note == "pid holding 0.55 m", timeout=30)
    browser.set_gui("target [m]", 5.0)  # typed; the browser then holds the box to the slider's end
    wait_for(lambda: "not used" in simulate.law_note)
    assert "target [m] must be 0.1 to 2, got" in simulate.law_note, simulate.law_note
    assert simulate.climb.law is not None and simulate.climb.law.target == pytest.approx(0.55 / 0.2232, rel=0.01)
