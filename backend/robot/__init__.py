"""The robot link: the XBee API-frame codec, ParkourLab's application messages, and (next) the
link, tracker input and the virtual robot. The protocol is written down in docs/protocol.md."""
