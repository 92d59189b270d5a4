"""Calibration: the model fitted to tracked touchdowns of the robot, their series and the model's
prediction of them, and the noise read off the residuals (docs/calibration.md).
"""
