from volanim_core.cli import main

raise SystemExit(main())
