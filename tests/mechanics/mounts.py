"""Mount inputs shared by the mechanics tests: the reference's Example 1 (optionally edited)."""

from support import ROOT

from align.io import read_toml
from mechanics.mount import Mount, mount_from_dict

EXAMPLE1 = ROOT / "examples" / "budget" / "example1.toml"


def example1(**changes) -> Mount:
    """Example 1's mount; ``section__field=value`` sets a field (None removes it)."""
    data = read_toml(EXAMPLE1)
    for key, value in changes.items():
        section, field = key.split("__")
        if value is None:
            data[section].pop(field, None)
        else:
            data[section][field] = value
    return mount_from_dict(data, "example1.toml")
