//! Which methods to skin and show, in order: one (a single view) or several side by side.

use super::Method;
use crate::{Error, Result};

/// One to four distinct skinning methods in display order.
///
/// A gap or a repeat cannot be represented, so whatever holds one (a viewer's view, a frame
/// header) always describes 1–4 meshes.
///
/// ```
/// use dqhand::skin::{Method, MethodSet};
///
/// let set = MethodSet::parse(&["lb", "DQB"])?; // names in any case, in display order
/// assert_eq!(set.as_slice(), [Method::Lb, Method::Dqb]);
/// assert!(set.contains(Method::Dqb) && !set.contains(Method::Qb));
/// let repeated = MethodSet::new(&[Method::Qb, Method::Lb, Method::Qb]).unwrap_err();
/// assert!(matches!(repeated, dqhand::Error::Methods(_)));
/// assert!(repeated.to_string().contains("\"qb\" given twice"), "{repeated}");
/// assert!(matches!(MethodSet::parse(&["dqs"]), Err(dqhand::Error::UnknownName { .. })));
/// # Ok::<(), dqhand::Error>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct MethodSet {
    methods: [Method; 4],
    len: u8,
}

impl MethodSet {
    /// DQB alone: the paper's method.
    pub const DQB: Self = Self { methods: [Method::Dqb; 4], len: 1 };
    /// LB, QB and DQB, in the paper's order.
    pub const PAPER: Self = Self { methods: [Method::Lb, Method::Qb, Method::Dqb, Method::Dqb], len: 3 };
    /// All four, the paper's three and CoR: the split view.
    pub const ALL: Self = Self { methods: Method::ALL, len: 4 };

    /// The methods given, in that order.
    ///
    /// # Errors
    /// [`Error::Methods`] if there are none, more than four, or one is repeated.
    pub fn new(methods: &[Method]) -> Result<Self> {
        if methods.is_empty() || methods.len() > Method::ALL.len() {
            return Err(Error::Methods(format!("{} methods (1 to 4)", methods.len())));
        }
        let mut set = Self { methods: [methods[0]; 4], len: 0 };
        for &m in methods {
            if set.contains(m) {
                return Err(Error::Methods(format!("method {:?} given twice", m.as_str())));
            }
            set.methods[usize::from(set.len)] = m;
            set.len += 1;
        }
        Ok(set)
    }

    /// The methods named (`lb`, `qb`, `dqb`, `cor`, in any case), in that order.
    ///
    /// # Errors
    /// [`Error::UnknownName`] for a name that is no method, else as [`Self::new`].
    pub fn parse<S: AsRef<str>>(names: &[S]) -> Result<Self> {
        let methods: Vec<Method> = names.iter().map(|n| n.as_ref().parse()).collect::<Result<_>>()?;
        Self::new(&methods)
    }

    /// The methods, in order.
    #[must_use]
    pub fn as_slice(&self) -> &[Method] {
        &self.methods[..usize::from(self.len)]
    }

    /// How many methods (1 to 4).
    #[must_use]
    pub fn len(&self) -> usize {
        usize::from(self.len)
    }

    /// Never true: a set holds at least one method.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Whether `method` is in the set.
    #[must_use]
    pub fn contains(&self, method: Method) -> bool {
        self.as_slice().contains(&method)
    }
}

/// Two sets are equal when they list the same methods in the same order.
impl PartialEq for MethodSet {
    fn eq(&self, other: &Self) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl Eq for MethodSet {}

impl core::hash::Hash for MethodSet {
    fn hash<H: core::hash::Hasher>(&self, state: &mut H) {
        self.as_slice().hash(state);
    }
}

impl Default for MethodSet {
    fn default() -> Self {
        Self::DQB
    }
}
