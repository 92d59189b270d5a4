"""The catalog: what this service offers (controllers, job kinds), read by the panel to fill its choosers."""

from __future__ import annotations

from fastapi import APIRouter

from backend import schemas
from backend.services import catalog as catalogs

router = APIRouter(prefix="/api/v1/catalog", tags=["service"])


@router.get("", response_model=schemas.Catalog)
async def get_catalog() -> schemas.Catalog:
    """The registered controllers and job kinds, in the order choosers list them."""
    return catalogs.catalog()
