// Keeps pwl_analysis a real library while it has no other translation unit.
