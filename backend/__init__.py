"""ParkourLab's service side: the command line now; the FastAPI service, store and robot link next."""
