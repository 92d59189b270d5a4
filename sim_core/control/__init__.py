"""Controlling the climb: the control laws as data (:mod:`.laws`), their compiled controllers, the height
controller, designs (PID gains, the return-map LQR, deadbeat with its viability guard), the closed loop jump
by jump, and the control study that compares them (docs/analyses.md).
"""
