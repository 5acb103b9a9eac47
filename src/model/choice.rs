//! Options with a fixed set of values (a mode, a skinning method, a bake strategy): each value has an id, which
//! files, reports and the command line use, and a description for people. The app lists the values in its menus
//! and the command line in its help from the same table.

/// A fixed set of values, each with an id and a description.
pub trait Choice: Copy + PartialEq + Send + Sync + 'static {
    /// Every value, in the order menus and help list them.
    const ALL: &'static [Self];

    /// The value's id: kebab-case, as the JSON reports write it.
    fn id(self) -> &'static str;

    /// What the value means, in a few words.
    fn description(self) -> &'static str;

    /// The value whose id is `id`.
    fn from_id(id: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|v| v.id() == id)
    }
}
