import sys
from pathlib import Path

# the tests import the runner, the oracle and the driver as plain modules
sys.path.insert(0, str(Path(__file__).resolve().parent))
