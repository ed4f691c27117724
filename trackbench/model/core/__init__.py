"""The model's shared ground: index tables (plain and compiled), the bundles the kernels
take, compile options and the elementary functions that round alike everywhere."""
