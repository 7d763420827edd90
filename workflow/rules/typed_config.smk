# Types the configuration before it is validated (no rules here).
import re

_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


def typed(value, nested=False):
    """Numbers inside mappings and lists as numbers: snakemake --config passes the values of a
    nested override ('paper_contact={radius: 3.0e-6, ...}') as text, and YAML 1.1 reads 1.776e9
    as text too. Top-level values (paths, names) are left as they are."""
    if isinstance(value, dict):
        return {k: typed(v, True) for k, v in value.items()}
    if isinstance(value, list):
        return [typed(v, True) for v in value]
    if nested and isinstance(value, str) and _NUMBER.fullmatch(value.strip()):
        text = value.strip()
        return int(text) if re.fullmatch(r"[+-]?\d+", text) else float(text)
    return value


config.update({key: typed(value) for key, value in config.items()})
