"""numpy/scipy only: the paper's data, the scene format, the result schema, and an independent
engine for the whole joint. Never imports exudyn, cardan_exudyn or rigdata."""
