//! dressform: personalized symmetric mannequins from 3D body scans.
