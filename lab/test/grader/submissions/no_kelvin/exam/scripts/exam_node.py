#!/usr/bin/env python3
# Noeud exam : calcule l'altitude du drone et allume la LED ALT WARN

import math
import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

# constantes de l'equation (1)
P0 = 101325.0
MU = 0.0289644
G = 9.80665
R = 8.31432

# dernieres valeurs recues
temperature = None
pression = None


def cb_temperature(msg):
    # on garde la derniere temperature
    global temperature
    temperature = msg.data


def cb_pression(msg):
    # on garde la derniere pression
    global pression
    pression = msg.data


if __name__ == '__main__':
    rospy.init_node('exam')
    seuil = rospy.get_param('~seuil')               # seuil d'altitude (m)
    rospy.Subscriber('/temperature', Float32, cb_temperature)
    rospy.Subscriber('/pressure', Float32, cb_pression)
    pub = rospy.Publisher('/altitude', Float32, queue_size=10)
    led = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)
    boucle = rospy.Rate(10)                         # 10 Hz
    compteur = 0                                    # nombre de tours au dessus du seuil
    alerte = False
    while not rospy.is_shutdown():
        if temperature is not None and pression is not None:
            # altitude : h = R T / (mu g) ln(P0 / P)
            altitude = R * temperature / (MU * G) * math.log(P0 / pression)
            pub.publish(altitude)
            if altitude > seuil:
                compteur += 1
            else:
                compteur = 0
            if compteur >= 50 and not alerte:        # 50 tours de 0.1 s = 5 s
                led('WARNING')
                alerte = True
            if compteur == 0 and alerte:
                led('NORMAL')
                alerte = False
        boucle.sleep()
