"""The climb jump after jump, in real time: the sequencer the 3D view and the virtual robot drive (with the
noise and the chute's floor) and its records.
"""
