"""`python -m viscoadh_ros` runs the `viscoadh` command."""

import sys

from viscoadh_ros.cli.main import main

sys.exit(main())
