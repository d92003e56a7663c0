import sys

from eyeviz.cli import main

sys.exit(main())
