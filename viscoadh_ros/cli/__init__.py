"""The `viscoadh` command line tools."""
