import sys

try:
    from eyeviz.cli import main
except KeyboardInterrupt:  # Ctrl-C while Python imports eyeviz: no traceback
    print("eyeviz: interrupted", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
