"""The RSBB's referee-scored benchmarks (HGTKMH, HWV, HCFGAC and STB, ERL @Home 2017-19):
their referee items read from the run and ranked by the ERL rule."""
