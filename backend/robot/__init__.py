"""The robot link, written down in docs/protocol.md.

- :mod:`~backend.robot.xbee` — XBee API frames (escaped mode) and a resynchronising parser;
- :mod:`~backend.robot.messages` — ParkourLab's application messages (protocol v1);
- :mod:`~backend.robot.limits` — the servo limits every leg command is checked against;
- :mod:`~backend.robot.link` — the PC's side: a pyserial URL, heartbeats, safety (its states,
  error and e-stop results in :mod:`~backend.robot.link_types`);
- :mod:`~backend.robot.supervisor` — the link's one owner: the thread that alone opens, reconnects
  and closes it, on requests from everyone else;
- :mod:`~backend.robot.tracker` — body poses from the overhead camera (UDP datagrams, replays);
- :mod:`~backend.robot.touchdown` — touchdowns, section states and height gains from poses;
- the virtual robot: :mod:`~backend.robot.virtual` (its radio over TCP),
  :mod:`~backend.robot.firmware` (the robot's state machine) and :mod:`~backend.robot.climber`
  (its body, the model climbing in real time, streamed as tracker datagrams).
"""
