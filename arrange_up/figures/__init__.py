"""Pictures: problems, shadows, heat maps and storyboards (matplotlib)."""
