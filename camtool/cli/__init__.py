"""The command-line shell (click only): parses options and calls the job runners."""
