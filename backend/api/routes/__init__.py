"""The API's routes, one module per resource; each is thin: route → service → repository."""
