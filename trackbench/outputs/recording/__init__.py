"""The rerun recording of a run: record.py writes it, entities.py names its paths, styles.py and
panels.py say how each entity and the viewer's layout look, soil_view.py draws the soil."""
