"""wavepath's tools. A package so that the studies and generators in its folders run as modules
from the repository root (`python3 -m tools.studies.mip_study`) and import the shared modules of
tools/wavepath_tools/ without touching sys.path; the scripts at this folder's top run as files
(`python3 tools/peers.py`)."""
