"""A MkDocs hook: a nav entry of OPTIONAL is kept only once its page exists (a page another
piece of work is writing), so the site builds strictly before and after it lands."""

from pathlib import Path

OPTIONAL: frozenset[str] = frozenset()  #: none pending now (results_aided.md has landed)


def _prune(items, docs: Path):
    out = []
    for item in items:
        if isinstance(item, dict):
            (title, target), = item.items()
            if isinstance(target, list):
                out.append({title: _prune(target, docs)})
            elif target in OPTIONAL and not (docs / target).exists():
                continue
            else:
                out.append(item)
        else:
            out.append(item)
    return out


def on_config(config, **kwargs):
    config["nav"] = _prune(config["nav"], Path(config["docs_dir"]))
    return config
