"""Unit constants shared by every stage (SI inside the library; see DESIGN.md, "Units")."""

SECONDS_PER_DAY = 86_400.0  # [s]
SECONDS_PER_WEEK = 7.0 * SECONDS_PER_DAY  # [s]
