"""weft front ends: the ``weft`` command (``app.cli``) and the desktop studio (``app.gui``)."""
