"""What a study is: study_file.py (the TOML file -> runs), rules.py (the checks the file's
tables share), search.py ([search]: its table and the scan and bisection), runid.py."""
