"""How a study is read: folder.py (a study file or results folder -> the study), summary.py
(the summary table), opening.py (open_study, open_study_dataset, open_limits), limits.py (a
search's state and limits), stacked.py (the runs' files as one lazy Dataset)."""
