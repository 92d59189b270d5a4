"""Request bodies the API tests share."""

RUN = {"controls": [{"psi0_deg": 30, "zeta0": 0.9}], "start": {"xdot": -0.93, "ydot": -0.17}, "jumps": 4}
