"""Writes the generated reference pages into the site at build time (mkdocs-gen-files):
they come from the code itself, so they cannot drift from it (docs/reference_pages.py)."""

import sys
from pathlib import Path

import mkdocs_gen_files

sys.path.insert(0, str(Path(__file__).parent))
import reference_pages  # noqa: E402

for name, page in (("cli", reference_pages.cli_page), ("scenario", reference_pages.scenario_page),
                   ("results-file", reference_pages.results_page),
                   ("limits", reference_pages.limits_page),
                   ("../explanation/decisions", reference_pages.decisions_page)):
    path = f"reference/{name}.md" if not name.startswith("..") else name[3:] + ".md"
    with mkdocs_gen_files.open(path, "w") as fh:
        fh.write(page())
    mkdocs_gen_files.set_edit_path(path, "reference_pages.py")
