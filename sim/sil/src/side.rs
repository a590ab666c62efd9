//! The robot's two sides, one ankle node each.

use protocol::NodeId;
use serde::Serialize;

/// A physical side of the robot, i.e. one ankle node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub enum Side {
    /// The left ankle ([`NodeId::LeftAnkle`], node 2).
    Left,
    /// The right ankle ([`NodeId::RightAnkle`], node 3).
    Right,
}

impl Side {
    /// Both sides, left first (the order nodes are ticked and reported in).
    pub const BOTH: [Side; 2] = [Side::Left, Side::Right];

    /// The protocol's node.
    pub const fn node(self) -> NodeId {
        match self {
            Side::Left => NodeId::LeftAnkle,
            Side::Right => NodeId::RightAnkle,
        }
    }

    /// The other side.
    pub const fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }

    /// Index 0 (left) or 1 (right).
    pub const fn index(self) -> usize {
        match self {
            Side::Left => 0,
            Side::Right => 1,
        }
    }

    /// The bus node name (`left`, `right`), as `FaultSpec`s name it.
    pub const fn bus_name(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }
}
