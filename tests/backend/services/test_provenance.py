"""The code version stored runs and jobs are stamped with."""

from backend.services.provenance import current_code_version


def test_code_version_is_stable_and_fits_its_column():
    version = current_code_version()
    assert version == current_code_version() and 0 < len(version) <= 64
