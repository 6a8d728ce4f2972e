"""weft front ends: the ``weft`` command (``weft.app.cli``) and the desktop studio (``weft.app.gui``)."""
