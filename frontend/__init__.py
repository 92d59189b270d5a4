"""The browser control panel and the viser 3D view (issue 7)."""
