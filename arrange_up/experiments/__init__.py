"""The thesis's experiments as commands: transition comparison and search table (chapter 3) and
the fixture-repair sweep (chapter 4)."""
