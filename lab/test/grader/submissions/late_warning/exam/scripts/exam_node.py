#!/usr/bin/env python3
# Noeud d'examen : altitude du drone a partir de la temperature et de la pression.
import math
import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

mesures = {'temperature': None, 'pression': None}  # degres Celsius, Pa


def memorise(nom):
    """Un callback qui range la derniere valeur recue sous ``nom``."""
    def callback(msg):
        mesures[nom] = msg.data
    return callback


def altitude(t, p):
    # equation (1) : h = R.T / (M.g) . ln(P0 / P), T en Kelvin
    return 8.31432 * (t + 273.15) / (0.0289644 * 9.80665) * math.log(101325.0 / p)


rospy.init_node('exam')
seuil = rospy.get_param('~seuil')
rospy.Subscriber('/temperature', Float32, memorise('temperature'))
rospy.Subscriber('/pressure', Float32, memorise('pression'))
pub = rospy.Publisher('/altitude', Float32, queue_size=10)
alerte = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)
boucle = rospy.Rate(10)
compteur = 0      # nombre de tours au-dessus du seuil
en_alerte = False
while not rospy.is_shutdown():
    if None not in mesures.values():
        h = altitude(mesures['temperature'], mesures['pression'])
        pub.publish(h)
        compteur = compteur + 1 if h > seuil else 0
        # 5 s = 500 tours de 10 ms
        if compteur >= 500 and not en_alerte:
            alerte('WARNING')
            en_alerte = True
        elif compteur == 0 and en_alerte:
            alerte('NORMAL')
            en_alerte = False
    boucle.sleep()
