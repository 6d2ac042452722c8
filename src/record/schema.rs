//! The columns of a run folder's CSV files, defined once: the recorder writes them, and the
//! viewer, `shoal diff` and the tests read them by these names.

/// A column of `trajectories.csv` (one row per agent per recorded tick), in file order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(usize)]
pub enum TrajColumn {
    /// Tick number.
    Tick,
    /// Simulated seconds.
    Time,
    /// Agent id.
    Id,
    /// Species name.
    Species,
    /// Position x.
    X,
    /// Position y (up).
    Y,
    /// Position z.
    Z,
    /// Heading x.
    Fx,
    /// Heading y.
    Fy,
    /// Heading z.
    Fz,
    /// Speed (units/s).
    Speed,
    /// Current behavior's name.
    Behavior,
    /// Behaviors on the interruption stack.
    StackDepth,
    /// Hunger drive.
    Hunger,
    /// Libido drive.
    Libido,
    /// Fear drive.
    Fear,
    /// Swimming cycle phase.
    SwimPhase,
    /// Tail bend.
    TailBend,
}

/// Names of [`TrajColumn`]'s columns, in file order.
pub const TRAJECTORY_COLUMNS: [&str; 18] = [
    "tick",
    "time",
    "id",
    "species",
    "x",
    "y",
    "z",
    "fx",
    "fy",
    "fz",
    "speed",
    "behavior",
    "stack_depth",
    "hunger",
    "libido",
    "fear",
    "swim_phase",
    "tail_bend",
];

/// A column of `food.csv` (one row per food item per recorded tick), in file order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(usize)]
pub enum FoodColumn {
    /// Tick number.
    Tick,
    /// Food item id.
    Id,
    /// Position x.
    X,
    /// Position y (up).
    Y,
    /// Position z.
    Z,
}

/// Names of [`FoodColumn`]'s columns, in file order.
pub const FOOD_COLUMNS: [&str; 5] = ["tick", "id", "x", "y", "z"];

/// A header line: the names joined by commas.
pub fn header(columns: &[&str]) -> String {
    columns.join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn enum_order_matches_the_names() {
        assert_eq!(TRAJECTORY_COLUMNS[TrajColumn::Tick as usize], "tick");
        assert_eq!(TRAJECTORY_COLUMNS[TrajColumn::Species as usize], "species");
        assert_eq!(
            TRAJECTORY_COLUMNS[TrajColumn::Behavior as usize],
            "behavior"
        );
        assert_eq!(
            TRAJECTORY_COLUMNS[TrajColumn::StackDepth as usize],
            "stack_depth"
        );
        assert_eq!(
            TRAJECTORY_COLUMNS[TrajColumn::TailBend as usize],
            "tail_bend"
        );
        assert_eq!(FOOD_COLUMNS[FoodColumn::Z as usize], "z");
        assert_eq!(
            header(&TRAJECTORY_COLUMNS),
            "tick,time,id,species,x,y,z,fx,fy,fz,speed,behavior,stack_depth,hunger,libido,fear,swim_phase,tail_bend"
        );
    }
}
