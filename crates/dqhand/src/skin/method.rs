//! The three skinning methods the paper compares (section 4.4), and a fourth beyond it.

use core::fmt;

/// A skinning method.
///
/// ```
/// use dqhand::skin::Method;
///
/// assert_eq!("DQB".parse::<Method>()?, Method::Dqb);
/// assert_eq!(Method::Qb.to_string(), "qb");
/// assert_eq!(Method::ALL.map(Method::index), [0, 1, 2, 3]);
/// let unknown = "blend".parse::<Method>().unwrap_err().to_string();
/// assert_eq!(unknown, "unknown skinning method \"blend\"; valid: lb, qb, dqb, cor");
/// # Ok::<(), dqhand::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Method {
    /// Linear blending of matrices.
    Lb,
    /// Quaternion blending: rotations as quaternions, translations linearly.
    Qb,
    /// Dual quaternion blending, paper eq. (3)–(6).
    Dqb,
    /// Optimized centres of rotation (Le and Hodgins 2016): QB's rotation about a
    /// precomputed centre per vertex, moved by LB.
    Cor,
}

impl Method {
    /// All four: the paper's, then CoR.
    pub const ALL: [Method; 4] = [Method::Lb, Method::Qb, Method::Dqb, Method::Cor];

    /// The paper's three, in its Table 3 order.
    pub const PAPER: [Method; 3] = [Method::Lb, Method::Qb, Method::Dqb];

    /// The position in [`Self::ALL`] (0 LB, 1 QB, 2 DQB, 3 CoR): the index of per-method
    /// arrays and the method's code in the viewer stream.
    #[must_use]
    pub const fn index(self) -> usize {
        self as usize
    }

    /// `lb`, `qb`, `dqb` or `cor`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Method::Lb => "lb",
            Method::Qb => "qb",
            Method::Dqb => "dqb",
            Method::Cor => "cor",
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl core::str::FromStr for Method {
    type Err = crate::Error;
    /// `lb`, `qb`, `dqb` or `cor`, in any case; anything else is [`crate::Error::UnknownName`].
    fn from_str(s: &str) -> crate::Result<Self> {
        Self::ALL.into_iter().find(|m| m.as_str().eq_ignore_ascii_case(s)).ok_or_else(|| crate::Error::UnknownName {
            kind: "skinning method",
            name: s.to_owned(),
            valid: "lb, qb, dqb, cor".into(),
        })
    }
}
