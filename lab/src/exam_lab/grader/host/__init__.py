"""Root's side: makes the boxes (uids, namespaces, cgroups, limits) and is the only reader of what
comes out of them, as capped records checked against their schema."""
