"""Measured data from the test rig: readers, conditioning, measured efficiency (issue 5).

Empty for now: no reader or comparison exists yet.
"""
