"""Batch jobs over a whole library on Dask (issue 21): one task per input (and target), each
writing its outputs atomically and one manifest entry; a local cluster by default or a running
scheduler. Above the renderer and the editor's headless parts, below the command line."""
