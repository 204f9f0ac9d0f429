"""One module per ``c2n`` sub-command."""
